//! One Draco stream (bitstream 2.2, the version `KHR_draco_mesh_compression` specifies) decoded
//! under the load's budget. The decoder (`draco-oxide-decoder`, a Rust port of Draco's) sizes
//! its work from counts in the stream and does not report them, so they are read here first:
//! the header, the metadata (skipped), the connectivity counts, checked against the counts the
//! glTF accessors declare, then, after the connectivity alone is decoded, the attribute
//! descriptors. The decoder's working memory is charged from them (a bound, measured at several
//! times what it uses) before the stream is decoded whole.

use draco_oxide_core::bit_coder::Reader;
use draco_oxide_core::codec::header::EncoderMethod;
use draco_oxide_core::mesh::Mesh;

use crate::budget::Budget;

/// Decoder memory per triangle corner: corner tables, the corner-to-point map, the faces.
const BYTES_PER_CORNER: u64 = 64;
/// Decoder memory per position vertex: its corner, hole flag and traversal state.
const BYTES_PER_VERTEX: u64 = 32;
/// Decoder memory per attribute value component: the portable integer, predictions and the
/// dequantized value.
const BYTES_PER_COMPONENT: u64 = 32;
/// Decoder memory per attribute value: the point-to-value map and bookkeeping.
const BYTES_PER_VALUE: u64 = 16;
/// The reference decoder's limit on nested metadata.
const MAX_METADATA_DEPTH: usize = 1000;

/// What the glTF accessors say the stream holds.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Expected {
    /// Triangle corners: the index accessor's count (or the vertex count without one).
    pub corners: u64,
    /// Vertices: the attribute accessors' count.
    pub points: u64,
}

/// Decodes a Draco mesh stream whose counts agree with `expected`, charging the decoder's
/// memory to `budget` first. Errors are one line.
pub(crate) fn decode_mesh(
    bytes: &[u8],
    expected: Expected,
    budget: &mut Budget,
) -> Result<Mesh, String> {
    let mut cursor = Cursor { bytes, at: 0 };
    let method = read_header(&mut cursor)?;
    let counts = read_connectivity_counts(&mut cursor.clone(), method)?;
    counts.check(expected)?;
    let vertices = counts.vertices.max(expected.points);
    budget.charge(
        counts.faces * 3,
        BYTES_PER_CORNER,
        "decoding Draco connectivity",
    )?;
    budget.charge(vertices, BYTES_PER_VERTEX, "decoding Draco connectivity")?;

    // The connectivity alone, to reach the attribute descriptors.
    let rest = &bytes[cursor.at..];
    let mut reader = Reader::new(rest);
    draco_oxide_decoder::connectivity::decode_connectivity(&mut reader, method)
        .map_err(|e| format!("the Draco connectivity is malformed: {e}"))?;
    let mut attributes = Cursor {
        bytes: rest,
        at: rest.len() - reader.remaining(),
    };
    let components = read_attribute_components(&mut attributes, method)?;
    // Values per attribute: one per point (sequential), at most one per corner (edgebreaker).
    let values = match method {
        EncoderMethod::Sequential => expected.points,
        EncoderMethod::Edgebreaker => counts.faces * 3,
    };
    let per_value = components
        .checked_mul(BYTES_PER_COMPONENT)
        .and_then(|c| c.checked_add(BYTES_PER_VALUE))
        .ok_or("the Draco attributes are too large")?;
    budget.charge(values, per_value, "decoding Draco attributes")?;

    draco_oxide_decoder::decode_mesh(bytes).map_err(|e| format!("the Draco data is malformed: {e}"))
}

/// Triangle corners and vertices that a stream's header declares (vertices: the point count of
/// a sequential stream, the encoded vertices of an edgebreaker one).
pub(crate) fn header_counts(bytes: &[u8]) -> Result<(u64, u64), String> {
    let mut cursor = Cursor { bytes, at: 0 };
    let method = read_header(&mut cursor)?;
    let counts = read_connectivity_counts(&mut cursor, method)?;
    let encoded = counts.vertices - counts.split_symbols.min(counts.vertices);
    Ok((counts.faces.saturating_mul(3), encoded))
}

/// A byte cursor over the stream.
#[derive(Clone)]
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Cursor<'_> {
    fn u8(&mut self) -> Result<u8, String> {
        let b = *self
            .bytes
            .get(self.at)
            .ok_or("the Draco data ends early (truncated?)")?;
        self.at += 1;
        Ok(b)
    }

    fn skip(&mut self, n: u64) -> Result<(), String> {
        let end = usize::try_from(n)
            .ok()
            .and_then(|n| self.at.checked_add(n))
            .filter(|&end| end <= self.bytes.len())
            .ok_or("the Draco data ends early (truncated?)")?;
        self.at = end;
        Ok(())
    }

    /// An unsigned LEB128 value of at most 64 bits.
    fn varint(&mut self) -> Result<u64, String> {
        let mut value = 0u64;
        for shift in (0..64).step_by(7) {
            let b = self.u8()?;
            value |= u64::from(b & 0x7f) << shift;
            if b & 0x80 == 0 {
                return Ok(value);
            }
        }
        Err("a Draco count is longer than 64 bits".to_string())
    }
}

/// Reads the header (and skips the metadata); the connectivity method.
fn read_header(c: &mut Cursor) -> Result<EncoderMethod, String> {
    if !c.bytes.starts_with(b"DRACO") {
        return Err("the compressed data is not a Draco stream".to_string());
    }
    c.skip(5)?;
    let (major, minor, geometry) = (c.u8()?, c.u8()?, c.u8()?);
    if (major, minor) != (2, 2) {
        return Err(format!(
            "Draco bitstream {major}.{minor} is not the 2.2 that KHR_draco_mesh_compression specifies"
        ));
    }
    if geometry != 1 {
        return Err(format!(
            "the Draco data is not a triangle mesh (geometry type {geometry}); KHR_draco_mesh_compression holds triangles"
        ));
    }
    let method = match c.u8()? {
        0 => EncoderMethod::Sequential,
        1 => EncoderMethod::Edgebreaker,
        other => return Err(format!("unknown Draco connectivity method {other}")),
    };
    let flags = u16::from_le_bytes([c.u8()?, c.u8()?]);
    if flags & 0x8000 != 0 {
        let attribute_metadata = c.varint()?;
        for _ in 0..attribute_metadata {
            c.varint()?;
            skip_metadata(c, 0)?;
        }
        skip_metadata(c, 0)?;
    }
    Ok(method)
}

/// Skips one metadata block: named entries, then named sub-blocks.
fn skip_metadata(c: &mut Cursor, depth: usize) -> Result<(), String> {
    if depth > MAX_METADATA_DEPTH {
        return Err("the Draco metadata is nested too deeply".to_string());
    }
    let entries = c.varint()?;
    for _ in 0..entries {
        let name = c.u8()?;
        c.skip(u64::from(name))?;
        let size = c.varint()?;
        c.skip(size)?;
    }
    let blocks = c.varint()?;
    for _ in 0..blocks {
        let name = c.u8()?;
        c.skip(u64::from(name))?;
        skip_metadata(c, depth + 1)?;
    }
    Ok(())
}

/// The counts at the start of the connectivity section.
struct Counts {
    faces: u64,
    /// Points (sequential) or the most position vertices (edgebreaker: encoded vertices plus
    /// split symbols).
    vertices: u64,
    /// Edgebreaker symbols and split symbols (0 for sequential).
    symbols: u64,
    split_symbols: u64,
    sequential: bool,
}

fn read_connectivity_counts(c: &mut Cursor, method: EncoderMethod) -> Result<Counts, String> {
    match method {
        EncoderMethod::Sequential => {
            let faces = c.varint()?;
            let points = c.varint()?;
            Ok(Counts {
                faces,
                vertices: points,
                symbols: 0,
                split_symbols: 0,
                sequential: true,
            })
        }
        EncoderMethod::Edgebreaker => {
            c.u8()?; // traversal
            let encoded_vertices = c.varint()?;
            let faces = c.varint()?;
            c.u8()?; // attribute data
            let symbols = c.varint()?;
            let split_symbols = c.varint()?;
            // The decoder sizes its list of topology splits from this count: each split takes
            // at least two bytes of the stream.
            let splits = c.varint()?;
            if splits > (c.bytes.len() - c.at) as u64 / 2 {
                return Err("the Draco topology splits exceed the stream".to_string());
            }
            Ok(Counts {
                faces,
                vertices: encoded_vertices.saturating_add(split_symbols),
                symbols,
                split_symbols,
                sequential: false,
            })
        }
    }
}

impl Counts {
    /// The stream's counts must be the accessors' (and consistent) before anything is sized
    /// from them.
    fn check(&self, expected: Expected) -> Result<(), String> {
        let corners = self.faces.checked_mul(3);
        if corners != Some(expected.corners) {
            return Err(format!(
                "the Draco data holds {} triangles, but the accessors declare {} indices",
                self.faces, expected.corners
            ));
        }
        if self.sequential && self.vertices != expected.points {
            return Err(format!(
                "the Draco data holds {} vertices, but the accessors declare {}",
                self.vertices, expected.points
            ));
        }
        if self.symbols > self.faces
            || self.split_symbols > self.faces
            || self.vertices > expected.corners
        {
            return Err("the Draco connectivity counts are inconsistent".to_string());
        }
        Ok(())
    }
}

/// Reads the attribute descriptors; the sum of their component counts.
fn read_attribute_components(c: &mut Cursor, method: EncoderMethod) -> Result<u64, String> {
    let decoders = c.u8()?;
    if matches!(method, EncoderMethod::Edgebreaker) {
        // Per decoder: attribute data id, domain, traversal.
        c.skip(3 * u64::from(decoders))?;
    }
    let mut components = 0u64;
    for _ in 0..decoders {
        let count = c.varint()?;
        for _ in 0..count {
            c.skip(2)?; // attribute type, component type
            components += u64::from(c.u8()?);
            c.u8()?; // normalized
            c.varint()?; // unique id
        }
        c.skip(count)?; // one decoder type per attribute
    }
    Ok(components)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cursor(bytes: &[u8]) -> Cursor<'_> {
        Cursor { bytes, at: 0 }
    }

    #[test]
    fn varints_are_bounded_and_checked() {
        assert_eq!(cursor(&[0x96, 0x01]).varint(), Ok(150));
        assert!(cursor(&[0x80]).varint().is_err());
        assert!(cursor(&[0xff; 11])
            .varint()
            .unwrap_err()
            .contains("64 bits"));
    }

    #[test]
    fn headers_other_than_a_2_2_mesh_are_refused() {
        let header = |v: [u8; 2], geometry: u8| {
            let mut b = b"DRACO".to_vec();
            b.extend([v[0], v[1], geometry, 1, 0, 0]);
            b
        };
        assert!(read_header(&mut cursor(&header([2, 2], 1))).is_ok());
        let old = read_header(&mut cursor(&header([2, 1], 1))).unwrap_err();
        assert!(old.contains("2.1") && old.contains("2.2"), "{old}");
        let points = read_header(&mut cursor(&header([2, 2], 0))).unwrap_err();
        assert!(points.contains("not a triangle mesh"), "{points}");
        assert!(read_header(&mut cursor(b"PLY")).is_err());
        assert!(read_header(&mut cursor(b"DRACO\x02")).is_err());
    }

    #[test]
    fn counts_must_match_the_accessors() {
        let counts = Counts {
            faces: 12,
            vertices: 24,
            symbols: 12,
            split_symbols: 0,
            sequential: false,
        };
        let expected = Expected {
            corners: 36,
            points: 24,
        };
        assert!(counts.check(expected).is_ok());
        let wrong = Expected {
            corners: 30,
            ..expected
        };
        assert!(counts.check(wrong).unwrap_err().contains("12 triangles"));
        // A face count whose corner count overflows (the decoder would size tables from it).
        let huge = Counts {
            faces: u64::MAX / 3 + 1,
            ..counts
        };
        assert!(huge.check(expected).is_err());
        let lying = Counts {
            symbols: 13,
            ..counts
        };
        assert!(lying.check(expected).is_err());
    }
}
