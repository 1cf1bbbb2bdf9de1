//! Image and array files written a band of rows at a time, so a picture never has to be held
//! whole: PNG (8-bit RGBA, 16-bit gray) through `png`'s streaming encoder, PFM (rows placed
//! bottom-up by seeking, as the format stores them) and NumPy `.npy`. OpenEXR is not here: its
//! crate writes whole images only.
//!
//! Rows arrive top to bottom, any number at a time; [`RowWriter::finish`] checks that every
//! row came. The files are the same as the whole-image encoders of [`crate::output`] write for
//! PFM and `.npy`; PNG uses the same compression settings (balanced deflate, adaptive filter).

use std::cell::RefCell;
use std::io::{self, Seek, SeekFrom, Write};
use std::rc::Rc;

use crate::output::write_npy_header;

/// Rows of samples handed to a [`RowWriter`]: row-major, `width × channels` values a row.
#[derive(Clone, Copy, Debug)]
pub enum Rows<'a> {
    /// 8-bit values (PNG RGBA8).
    U8(&'a [u8]),
    /// 16-bit values (PNG gray16, `.npy` `<u2`).
    U16(&'a [u16]),
    /// 32-bit unsigned values (`.npy` `<u4`).
    U32(&'a [u32]),
    /// 32-bit floats (PFM, `.npy` `<f4`).
    F32(&'a [f32]),
}

impl<'a> Rows<'a> {
    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            Rows::U8(v) => v.len(),
            Rows::U16(v) => v.len(),
            Rows::U32(v) => v.len(),
            Rows::F32(v) => v.len(),
        }
    }

    /// Whether there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn kind(&self) -> SampleKind {
        match self {
            Rows::U8(_) => SampleKind::U8,
            Rows::U16(_) => SampleKind::U16,
            Rows::U32(_) => SampleKind::U32,
            Rows::F32(_) => SampleKind::F32,
        }
    }
}

/// The element type of a file's samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleKind {
    /// 8-bit unsigned.
    U8,
    /// 16-bit unsigned.
    U16,
    /// 32-bit unsigned.
    U32,
    /// 32-bit float.
    F32,
}

impl SampleKind {
    fn npy_descr(self) -> Option<&'static str> {
        match self {
            SampleKind::U8 => None,
            SampleKind::U16 => Some("<u2"),
            SampleKind::U32 => Some("<u4"),
            SampleKind::F32 => Some("<f4"),
        }
    }
}

/// A writer both the PNG encoder (which owns its output) and the [`RowWriter`] hold, so the
/// output can be taken back after the encoder finished.
struct Shared<W>(Rc<RefCell<W>>);

impl<W: Write> Write for Shared<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.borrow_mut().write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.0.borrow_mut().flush()
    }
}

enum Encoder<W: Write + Seek + 'static> {
    Png {
        stream: Box<png::StreamWriter<'static, Shared<W>>>,
        out: Rc<RefCell<W>>,
    },
    /// Rows are placed at `data_start + (height - 1 - y) × row bytes`.
    Pfm {
        out: W,
        data_start: u64,
    },
    Npy {
        out: W,
    },
}

/// A file being written a band of rows at a time (see the module documentation).
pub struct RowWriter<W: Write + Seek + 'static> {
    encoder: Encoder<W>,
    width: u32,
    height: u32,
    channels: usize,
    kind: SampleKind,
    /// The next row expected.
    next_row: u32,
    /// One row converted to file bytes, reused.
    scratch: Vec<u8>,
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

fn check_size(width: u32, height: u32) -> io::Result<()> {
    if width == 0 || height == 0 {
        return Err(invalid(format!("{width}x{height} is not an image size")));
    }
    Ok(())
}

impl<W: Write + Seek + 'static> RowWriter<W> {
    fn new(
        encoder: Encoder<W>,
        width: u32,
        height: u32,
        channels: usize,
        kind: SampleKind,
    ) -> Self {
        Self {
            encoder,
            width,
            height,
            channels,
            kind,
            next_row: 0,
            scratch: Vec::new(),
        }
    }

    fn png(
        out: W,
        width: u32,
        height: u32,
        color: png::ColorType,
        depth: png::BitDepth,
    ) -> io::Result<Self> {
        check_size(width, height)?;
        let out = Rc::new(RefCell::new(out));
        let mut encoder = png::Encoder::new(Shared(out.clone()), width, height);
        encoder.set_color(color);
        encoder.set_depth(depth);
        encoder.set_compression(png::Compression::Balanced);
        encoder.set_filter(png::Filter::Adaptive);
        let stream = encoder
            .write_header()
            .and_then(|w| w.into_stream_writer())
            .map_err(io::Error::other)?;
        let (channels, kind) = match (color, depth) {
            (png::ColorType::Rgba, _) => (4, SampleKind::U8),
            _ => (1, SampleKind::U16),
        };
        Ok(Self::new(
            Encoder::Png {
                stream: Box::new(stream),
                out,
            },
            width,
            height,
            channels,
            kind,
        ))
    }

    /// An 8-bit RGBA PNG (rows: [`Rows::U8`], 4 values a pixel).
    pub fn png_rgba8(out: W, width: u32, height: u32) -> io::Result<Self> {
        Self::png(
            out,
            width,
            height,
            png::ColorType::Rgba,
            png::BitDepth::Eight,
        )
    }

    /// A 16-bit grayscale PNG (rows: [`Rows::U16`], one value a pixel).
    pub fn png_gray16(out: W, width: u32, height: u32) -> io::Result<Self> {
        Self::png(
            out,
            width,
            height,
            png::ColorType::Grayscale,
            png::BitDepth::Sixteen,
        )
    }

    /// A greyscale little-endian PFM (rows: [`Rows::F32`], top row first, as everywhere here;
    /// the file stores them bottom-up).
    pub fn pfm(mut out: W, width: u32, height: u32) -> io::Result<Self> {
        check_size(width, height)?;
        write!(out, "Pf\n{width} {height}\n-1.0\n")?;
        let data_start = out.stream_position()?;
        Ok(Self::new(
            Encoder::Pfm { out, data_start },
            width,
            height,
            1,
            SampleKind::F32,
        ))
    }

    /// A C-order `.npy` array of shape `(height, width)` (`channels` 1) or `(height, width,
    /// channels)`, of `kind` (not [`SampleKind::U8`]).
    pub fn npy(
        mut out: W,
        width: u32,
        height: u32,
        channels: usize,
        kind: SampleKind,
    ) -> io::Result<Self> {
        check_size(width, height)?;
        let descr = kind
            .npy_descr()
            .ok_or_else(|| invalid("8-bit .npy arrays are not written".into()))?;
        let (h, w) = (height as usize, width as usize);
        match channels {
            1 => write_npy_header(&mut out, &[h, w], descr)?,
            0 => return Err(invalid("an array needs at least one channel".into())),
            c => write_npy_header(&mut out, &[h, w, c], descr)?,
        }
        Ok(Self::new(
            Encoder::Npy { out },
            width,
            height,
            channels,
            kind,
        ))
    }

    /// Rows written so far.
    pub fn rows_written(&self) -> u32 {
        self.next_row
    }

    /// Appends whole rows below those written so far.
    pub fn write_rows(&mut self, rows: Rows<'_>) -> io::Result<()> {
        if rows.kind() != self.kind {
            return Err(invalid(format!(
                "rows of {:?} given to a file of {:?}",
                rows.kind(),
                self.kind
            )));
        }
        let per_row = self.width as usize * self.channels;
        let count = rows.len() / per_row;
        if !rows.len().is_multiple_of(per_row) || count > (self.height - self.next_row) as usize {
            return Err(invalid(format!(
                "{} values are not whole rows of a {}x{} image with {} rows left",
                rows.len(),
                self.width,
                self.height,
                self.height - self.next_row
            )));
        }
        for r in 0..count {
            self.scratch.clear();
            let range = r * per_row..(r + 1) * per_row;
            // PNG stores 16-bit samples big-endian; PFM and .npy here are little-endian.
            let png = matches!(self.encoder, Encoder::Png { .. });
            match rows {
                Rows::U8(v) => self.scratch.extend_from_slice(&v[range]),
                Rows::U16(v) if png => {
                    self.scratch
                        .extend(v[range].iter().flat_map(|x| x.to_be_bytes()));
                }
                Rows::U16(v) => {
                    self.scratch
                        .extend(v[range].iter().flat_map(|x| x.to_le_bytes()));
                }
                Rows::U32(v) => {
                    self.scratch
                        .extend(v[range].iter().flat_map(|x| x.to_le_bytes()));
                }
                Rows::F32(v) => {
                    self.scratch
                        .extend(v[range].iter().flat_map(|x| x.to_le_bytes()));
                }
            }
            let y = self.next_row;
            match &mut self.encoder {
                Encoder::Png { stream, .. } => stream.write_all(&self.scratch)?,
                Encoder::Npy { out } => out.write_all(&self.scratch)?,
                Encoder::Pfm { out, data_start } => {
                    let row_bytes = self.scratch.len() as u64;
                    let at = *data_start + u64::from(self.height - 1 - y) * row_bytes;
                    out.seek(SeekFrom::Start(at))?;
                    out.write_all(&self.scratch)?;
                }
            }
            self.next_row += 1;
        }
        Ok(())
    }

    /// Ends the file (every row must have been written) and returns the output, flushed.
    pub fn finish(self) -> io::Result<W> {
        if self.next_row != self.height {
            return Err(invalid(format!(
                "only {} of {} rows were written",
                self.next_row, self.height
            )));
        }
        let mut out = match self.encoder {
            Encoder::Png { stream, out } => {
                stream.finish().map_err(io::Error::other)?;
                Rc::try_unwrap(out)
                    .map_err(|_| io::Error::other("the PNG encoder kept its output"))?
                    .into_inner()
            }
            Encoder::Pfm {
                mut out,
                data_start,
            } => {
                // Leave the position at the end of the file.
                let row_bytes = self.width as u64 * 4;
                out.seek(SeekFrom::Start(data_start + row_bytes * self.height as u64))?;
                out
            }
            Encoder::Npy { out } => out,
        };
        out.flush()?;
        Ok(out)
    }
}

/// A writer that cannot seek (standard output), for the formats that never seek (PNG, `.npy`):
/// seeking is an error.
#[derive(Debug)]
pub struct Unseekable<W>(pub W);

impl<W: Write> Write for Unseekable<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.0.flush()
    }
}

impl<W> Seek for Unseekable<W> {
    fn seek(&mut self, _: SeekFrom) -> io::Result<u64> {
        Err(io::Error::new(
            io::ErrorKind::Unsupported,
            "this output cannot seek",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::{decode_pfm, encode_npy, encode_pfm, NpyData};
    use std::io::Cursor;

    /// Writes `values` through `writer` in bands of `band` rows.
    fn in_bands<T: Copy>(
        mut writer: RowWriter<Cursor<Vec<u8>>>,
        values: &[T],
        row: usize,
        band: usize,
        rows: impl Fn(&[T]) -> Rows<'_>,
    ) -> Vec<u8> {
        for chunk in values.chunks(row * band) {
            writer.write_rows(rows(chunk)).expect("rows");
        }
        writer.finish().expect("finish").into_inner()
    }

    #[test]
    fn pfm_and_npy_equal_the_whole_image_encoders() {
        let (w, h) = (5u32, 7u32);
        let values: Vec<f32> = (0..w * h).map(|i| i as f32 * 0.5 - 3.0).collect();
        let mut whole = Vec::new();
        encode_pfm(&mut whole, w, h, &values).unwrap();
        for band in [1, 2, 3, 7] {
            let pfm = RowWriter::pfm(Cursor::new(Vec::new()), w, h).unwrap();
            let banded = in_bands(pfm, &values, w as usize, band, |v| Rows::F32(v));
            assert_eq!(banded, whole, "PFM in bands of {band}");
        }
        assert_eq!(decode_pfm(&whole).unwrap().2, values);

        let ids: Vec<u32> = (0..w * h * 3).map(|i| i * 70_001).collect();
        let mut whole = Vec::new();
        encode_npy(&mut whole, &[7, 5, 3], NpyData::U32(&ids)).unwrap();
        let npy = RowWriter::npy(Cursor::new(Vec::new()), w, h, 3, SampleKind::U32).unwrap();
        assert_eq!(in_bands(npy, &ids, 15, 2, |v| Rows::U32(v)), whole);
    }

    #[test]
    fn png_rows_decode_to_the_values_whatever_the_bands() {
        let (w, h) = (9u32, 6u32);
        let rgba: Vec<u8> = (0..w * h * 4).map(|i| (i * 37 % 251) as u8).collect();
        let gray: Vec<u16> = (0..w * h).map(|i| (i * 1237) as u16).collect();
        let mut files = Vec::new();
        for band in [1, 4, 6] {
            let png = RowWriter::png_rgba8(Cursor::new(Vec::new()), w, h).unwrap();
            let bytes = in_bands(png, &rgba, 4 * w as usize, band, |v| Rows::U8(v));
            let decoded = image::load_from_memory(&bytes).unwrap().into_rgba8();
            assert_eq!(decoded.into_raw(), rgba);
            files.push(bytes);
            let png = RowWriter::png_gray16(Cursor::new(Vec::new()), w, h).unwrap();
            let bytes = in_bands(png, &gray, w as usize, band, |v| Rows::U16(v));
            let decoded = image::load_from_memory(&bytes).unwrap().into_luma16();
            assert_eq!(decoded.into_raw(), gray);
        }
        assert!(
            files.windows(2).all(|f| f[0] == f[1]),
            "bands change the bytes"
        );
    }

    #[test]
    fn wrong_rows_are_errors() {
        let mut png = RowWriter::png_rgba8(Cursor::new(Vec::new()), 2, 2).unwrap();
        assert!(png.write_rows(Rows::U16(&[0; 8])).is_err(), "wrong type");
        assert!(png.write_rows(Rows::U8(&[0; 7])).is_err(), "not whole rows");
        assert!(png.write_rows(Rows::U8(&[0; 24])).is_err(), "too many rows");
        png.write_rows(Rows::U8(&[0; 8])).unwrap();
        assert!(png.finish().is_err(), "a row missing");
        assert!(RowWriter::npy(Cursor::new(Vec::new()), 2, 2, 1, SampleKind::U8).is_err());
        assert!(RowWriter::pfm(Cursor::new(Vec::new()), 0, 2).is_err());
    }
}
