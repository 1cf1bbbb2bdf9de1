//! KTX2 images (`KHR_texture_basisu`, or a KTX2 file wherever a PNG could be): Basis Universal
//! ETC1S and UASTC LDR transcoded to RGBA8, and the uncompressed 8-bit RGB / RGBA formats.
//!
//! The container is read and validated with the `ktx2` crate; Basis Universal data is
//! transcoded by `basisu` (pure Rust, a port of the reference transcoder: a corrupt file is an
//! error or at worst a panic, caught and turned into this image's error, never a crash of the
//! process).
//! Before anything is transcoded the texture's size is checked against
//! [`MAX_TEXTURE_SIZE`](kantele_rules::shade::texture::MAX_TEXTURE_SIZE) and its decoded
//! memory (every level it will decode) charged to the load's budget, and every level size the
//! transcoder would allocate from the file is checked against the size the header implies.
//!
//! A file that holds the complete mip chain (down to 1 × 1, every level of the size the chain
//! rules give and of the byte length its format implies) has every level decoded and kept as
//! the file gives it ([`Texture::from_rgba8_levels`]). Otherwise, or when a smaller level fails
//! to decode, level 0 is decoded and the texture builds its own chain from it
//! ([`Texture::from_rgba8`]); a file with only some of the smaller levels has them ignored.

use kantele_rules::shade::texture::{ColorSpace, Texture, MAX_TEXTURE_SIZE};
use ktx2::{Format, SupercompressionScheme, TransferFunction};

use crate::budget::Budget;
use crate::texture_util::{ImageError, TEXTURE_BYTES_PER_TEXEL};

/// The 12 bytes a KTX2 file starts with.
const KTX2_MAGIC: [u8; 12] = [
    0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, b'\r', b'\n', 0x1A, b'\n',
];

/// Bytes per texel the transcoder needs besides its RGBA8 output: the Zstandard-inflated level
/// of UASTC (one byte a texel) and the per-block indices of ETC1S (a quarter byte a texel each
/// for colour and alpha), rounded up.
const TRANSCODER_SCRATCH_PER_TEXEL: u64 = 2;

/// Whether `bytes` are to be read as a KTX2 file: they start with the KTX2 identifier, or they
/// are declared `image/ktx2` and are no other image format the loader knows (the data decides
/// first, as for the other formats: files often declare the wrong MIME type).
pub(crate) fn is_ktx2(bytes: &[u8], mime_type: Option<&str>) -> bool {
    bytes.starts_with(&KTX2_MAGIC)
        || (mime_type == Some("image/ktx2") && image::guess_format(bytes).is_err())
}

/// What the KTX2 file holds, as far as decoding is concerned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Content {
    /// Basis Universal ETC1S (BasisLZ supercompression).
    Etc1s,
    /// Basis Universal UASTC LDR, plain or Zstandard-supercompressed.
    Uastc,
    /// Uncompressed 8-bit texels with this many channels (3: RGB, 4: RGBA).
    Plain { channels: u32 },
}

/// What decodes a level: the Basis Universal transcoder (boxed: it is large), opened once for
/// all levels, or the file's own uncompressed bytes.
enum LevelDecoder<'a> {
    /// ETC1S or UASTC.
    Basis(Box<basisu::Transcoder<'a>>),
    /// Uncompressed texels.
    Plain,
}

/// A validated KTX2 file: its header facts, ready to decode.
struct Ktx2File<'a> {
    reader: ktx2::Reader<&'a [u8]>,
    content: Content,
    width: u32,
    height: u32,
}

fn decode_error(message: impl Into<String>) -> ImageError {
    ImageError::Decode(message.into())
}

impl<'a> Ktx2File<'a> {
    /// Parses and validates the header, the level index and the data format descriptor; an
    /// error for everything this loader does not decode (cube maps, arrays, 3D and 1D
    /// textures, other formats: the message names the format).
    fn parse(bytes: &'a [u8]) -> Result<Self, ImageError> {
        let reader = caught("reader", || ktx2::Reader::new(bytes))?
            .map_err(|e| decode_error(format!("not a valid KTX2 file: {e}")))?;
        let header = reader.header();
        let (width, height) = (header.pixel_width, header.pixel_height);
        if header.pixel_depth > 0 {
            return Err(decode_error("the KTX2 file is a 3D texture"));
        }
        if header.face_count != 1 {
            return Err(decode_error("the KTX2 file is a cube map"));
        }
        if header.layer_count > 1 {
            return Err(decode_error(format!(
                "the KTX2 file is an array of {} textures",
                header.layer_count
            )));
        }
        if width == 0 || height == 0 || width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
            return Err(decode_error(format!(
                "KTX2 image size {width}x{height} is outside 1..={MAX_TEXTURE_SIZE}"
            )));
        }
        let scheme = header.supercompression_scheme;
        let model = reader.color_model();
        let content = match (header.format, model, scheme) {
            (None, Some(ktx2::ColorModel::ETC1S), Some(SupercompressionScheme::BasisLZ)) => {
                Content::Etc1s
            }
            (None, Some(ktx2::ColorModel::UASTC), None | Some(SupercompressionScheme::Zstandard)) => {
                Content::Uastc
            }
            (None, model, _) => {
                return Err(decode_error(format!(
                    "KTX2 colour model {} with supercompression {} is not supported (Basis Universal ETC1S and UASTC are)",
                    model.map_or("none".to_string(), |m| format!("{m:?}")),
                    scheme_name(scheme),
                )))
            }
            (Some(format), _, _) => {
                let channels = match format {
                    Format::R8G8B8A8_UNORM | Format::R8G8B8A8_SRGB => 4,
                    Format::R8G8B8_UNORM | Format::R8G8B8_SRGB => 3,
                    other => {
                        return Err(decode_error(format!(
                            "KTX2 format {other:?} is not supported (Basis Universal and 8-bit RGB / RGBA are)"
                        )))
                    }
                };
                if !matches!(scheme, None | Some(SupercompressionScheme::Zstandard)) {
                    return Err(decode_error(format!(
                        "KTX2 supercompression {} of {format:?} is not supported",
                        scheme_name(scheme)
                    )));
                }
                Content::Plain { channels }
            }
        };
        let file = Self {
            reader,
            content,
            width,
            height,
        };
        file.check_level0()?;
        Ok(file)
    }

    /// The size of level `index` in texels: `max(1, width >> index)` × `max(1, height >>
    /// index)`.
    fn level_dimensions(&self, index: u32) -> (u32, u32) {
        let halve = |size: u32| size.checked_shr(index).unwrap_or(0).max(1);
        (halve(self.width), halve(self.height))
    }

    /// Level `index`'s bytes once decompressed, as the header implies them (`None` for ETC1S,
    /// whose size is not fixed).
    fn level_size(&self, index: u32) -> Option<u64> {
        let (w, h) = self.level_dimensions(index);
        let (w, h) = (u64::from(w), u64::from(h));
        match self.content {
            Content::Etc1s => None,
            Content::Uastc => Some(w.div_ceil(4) * h.div_ceil(4) * 16),
            Content::Plain { channels } => Some(w * h * u64::from(channels)),
        }
    }

    /// Checks level 0's recorded sizes against the header (see [`Ktx2File::check_level`]).
    fn check_level0(&self) -> Result<(), ImageError> {
        if self.reader.levels().len() == 0 {
            return Err(decode_error("the KTX2 file has no image levels"));
        }
        self.check_level(0)
    }

    /// Checks level `index`'s recorded sizes against the header: the transcoder allocates a
    /// Zstandard level's recorded uncompressed size as it is, so a wrong one is refused here.
    fn check_level(&self, index: u32) -> Result<(), ImageError> {
        let level = self
            .reader
            .levels()
            .nth(index as usize)
            .ok_or_else(|| decode_error(format!("the KTX2 file has no level {index}")))?;
        let Some(expected) = self.level_size(index) else {
            return Ok(());
        };
        let zstd = self.reader.header().supercompression_scheme.is_some();
        let (what, actual) = if zstd {
            ("decompressed", level.uncompressed_byte_length)
        } else {
            ("stored", level.data.len() as u64)
        };
        if actual != expected {
            let (w, h) = self.level_dimensions(index);
            return Err(decode_error(format!(
                "KTX2 level {index} holds {actual} {what} bytes, but a {w}x{h} image needs {expected}"
            )));
        }
        Ok(())
    }

    /// How many levels the file's complete mip chain has, when it holds one (every level down
    /// to 1 × 1, each of the size its format implies); `None` when it holds only level 0, some
    /// of the levels, or levels of the wrong size.
    fn complete_chain(&self) -> Option<u32> {
        let full = 32 - self.width.max(self.height).leading_zeros();
        let stored = u32::try_from(self.reader.levels().len()).ok()?;
        (full > 1 && stored == full && (1..full).all(|i| self.check_level(i).is_ok()))
            .then_some(full)
    }

    /// The colour space the file declares (its DFD transfer function), if it declares one.
    fn declared_color_space(&self) -> Option<ColorSpace> {
        match self.reader.transfer_function()? {
            TransferFunction::SRGB => Some(ColorSpace::Srgb),
            TransferFunction::Linear => Some(ColorSpace::Linear),
            _ => None,
        }
    }

    /// Whether rows are stored bottom first (`KTXorientation` `ru`); glTF and the loader's
    /// textures want the top row first (`rd`, the default).
    fn bottom_up(&self) -> bool {
        self.reader
            .key_value_data()
            .find(|(key, _)| *key == "KTXorientation")
            .is_some_and(|(_, value)| value.get(1) == Some(&b'u'))
    }

    /// What decodes the file's levels: for Basis Universal, the transcoder opened on the file
    /// (an error for a Basis Universal video).
    fn level_decoder(&self) -> Result<LevelDecoder<'_>, ImageError> {
        match self.content {
            Content::Etc1s | Content::Uastc => {
                let data = self.reader.data();
                let transcoder =
                    caught("transcoder", || basisu::Transcoder::new(data))?.map_err(|e| {
                        decode_error(format!("cannot transcode KTX2: {}", basis_error(&e)))
                    })?;
                if transcoder.is_video() {
                    return Err(decode_error("the KTX2 file is a Basis Universal video"));
                }
                Ok(LevelDecoder::Basis(Box::new(transcoder)))
            }
            Content::Plain { .. } => Ok(LevelDecoder::Plain),
        }
    }

    /// Level `index` as RGBA8, rows top first.
    fn decode_level(&self, decoder: &LevelDecoder<'_>, index: u32) -> Result<Vec<u8>, ImageError> {
        let (width, height) = self.level_dimensions(index);
        let mut rgba = match (decoder, self.content) {
            (LevelDecoder::Basis(transcoder), _) => caught("transcoder", || {
                transcoder.transcode(
                    index,
                    basisu::TargetFormat::Rgba32,
                    basisu::DecodeFlags::NONE,
                )
            })?
            .map_err(|e| decode_error(format!("cannot transcode KTX2: {}", basis_error(&e))))?,
            (LevelDecoder::Plain, Content::Plain { channels }) => {
                let level =
                    self.reader.levels().nth(index as usize).ok_or_else(|| {
                        decode_error(format!("the KTX2 file has no level {index}"))
                    })?;
                let inflated;
                let texels = match self.reader.header().supercompression_scheme {
                    Some(_) => {
                        let size = level.uncompressed_byte_length;
                        inflated = caught("Zstandard decoder", || inflate_zstd(level.data, size))??;
                        &inflated[..]
                    }
                    None => level.data,
                };
                match channels {
                    4 => texels.to_vec(),
                    _ => texels
                        .chunks_exact(3)
                        .flat_map(|c| [c[0], c[1], c[2], 255])
                        .collect(),
                }
            }
            (LevelDecoder::Plain, _) => {
                return Err(decode_error("Basis Universal data without its transcoder"))
            }
        };
        if rgba.len() != width as usize * height as usize * 4 {
            return Err(decode_error(format!(
                "the KTX2 decoder gave {} bytes for a {width}x{height} image",
                rgba.len(),
            )));
        }
        if self.bottom_up() {
            flip_rows(&mut rgba, width as usize * 4);
        }
        Ok(rgba)
    }

    /// The file's smaller levels, 1 to `count - 1`, as RGBA8 rows top first; `None` when one
    /// of them does not decode.
    fn decode_smaller_levels(
        &self,
        decoder: &LevelDecoder<'_>,
        count: u32,
    ) -> Option<Vec<Vec<u8>>> {
        (1..count)
            .map(|index| self.decode_level(decoder, index).ok())
            .collect()
    }
}

/// A Zstandard-supercompressed level inflated to exactly `size` bytes (checked against the
/// header before, so within the budget).
fn inflate_zstd(compressed: &[u8], size: u64) -> Result<Vec<u8>, ImageError> {
    use std::io::Read;
    let corrupt =
        |e: &dyn std::fmt::Display| decode_error(format!("corrupt Zstandard level in KTX2: {e}"));
    let mut decoder = ruzstd::StreamingDecoder::new(compressed).map_err(|e| corrupt(&e))?;
    let mut out = vec![0; size as usize];
    decoder.read_exact(&mut out).map_err(|e| corrupt(&e))?;
    Ok(out)
}

/// Runs a dependency's code (`what`: the reader, the transcoder, the Zstandard decoder) with its
/// panics caught: a known way such code fails on corrupt data, turned into a one-line error for
/// this image instead of a failed load.
fn caught<T>(what: &str, f: impl FnOnce() -> T) -> Result<T, ImageError> {
    crate::quiet_panic::catch(f)
        .map_err(|m| decode_error(format!("malformed KTX2 file (the {what} failed: {m})")))
}

/// Swaps rows top for bottom.
fn flip_rows(rgba: &mut [u8], row_bytes: usize) {
    let rows = rgba.len() / row_bytes.max(1);
    for y in 0..rows / 2 {
        let (top, bottom) = rgba.split_at_mut((rows - 1 - y) * row_bytes);
        top[y * row_bytes..(y + 1) * row_bytes].swap_with_slice(&mut bottom[..row_bytes]);
    }
}

fn scheme_name(scheme: Option<SupercompressionScheme>) -> String {
    scheme.map_or("none".to_string(), |s| format!("{s:?}"))
}

/// The transcoder's error in words.
fn basis_error(error: &basisu::Error) -> String {
    match error {
        basisu::Error::Truncated => "the file is truncated".to_string(),
        basisu::Error::InvalidData => "corrupt or unsupported Basis Universal data".to_string(),
        other => format!("{other:?}"),
    }
}

/// The size of a KTX2 image from its header (nothing is decoded).
pub(crate) fn ktx2_size(bytes: &[u8]) -> Result<(u32, u32), ImageError> {
    let file = Ktx2File::parse(bytes)?;
    Ok((file.width, file.height))
}

/// Decodes a KTX2 image into a texture whose texels are encoded in `color_space` (decided by
/// the texture's use, as for every image), after charging the texture's memory and the
/// decoder's to `budget`: with the file's own mip levels when it holds the complete chain, else
/// level 0 with a chain the texture builds.
pub(crate) fn decode_ktx2(
    bytes: &[u8],
    color_space: ColorSpace,
    budget: &mut Budget,
) -> Result<Texture, ImageError> {
    let file = Ktx2File::parse(bytes)?;
    let (width, height) = (file.width, file.height);
    let chain = file.complete_chain();
    // The decoded RGBA8 of every level read (4 bytes a texel, 4/3 of that with the smaller
    // levels, rounded up), besides the texture and the transcoder's scratch.
    let decoded_per_texel = if chain.is_some() { 6 } else { 4 };
    budget
        .charge(
            u64::from(width) * u64::from(height),
            TEXTURE_BYTES_PER_TEXEL + decoded_per_texel + TRANSCODER_SCRATCH_PER_TEXEL,
            &format!("a {width}x{height} KTX2 texture"),
        )
        .map_err(ImageError::Budget)?;
    let decoder = file.level_decoder()?;
    let level0 = file.decode_level(&decoder, 0)?;
    let to_error = |e: kantele_rules::error::RenderError| ImageError::Decode(e.to_string());
    if let Some(smaller) = chain.and_then(|count| file.decode_smaller_levels(&decoder, count)) {
        let levels: Vec<&[u8]> = std::iter::once(&level0[..])
            .chain(smaller.iter().map(Vec::as_slice))
            .collect();
        // Checked level by level above; a chain the texture still refuses falls back too.
        if let Ok(texture) = Texture::from_rgba8_levels(width, height, &levels, color_space) {
            return Ok(texture);
        }
    }
    Texture::from_rgba8(width, height, &level0, color_space).map_err(to_error)
}

/// A note when a KTX2 image declares another colour space (its transfer function) than the one
/// its use gives it; `None` for other images and when they agree.
pub(crate) fn color_space_note(bytes: &[u8], color_space: ColorSpace) -> Option<String> {
    if !is_ktx2(bytes, None) {
        return None;
    }
    let declared = Ktx2File::parse(bytes).ok()?.declared_color_space()?;
    (declared != color_space).then(|| {
        let name = |c: ColorSpace| match c {
            ColorSpace::Srgb => "sRGB",
            ColorSpace::Linear => "linear",
        };
        format!(
            "the KTX2 file declares {} texels, but the texture's use makes them {}; read as {}",
            name(declared),
            name(color_space),
            name(color_space)
        )
    })
}

/// Body of the `ktx2` fuzz target ([`crate::texture_util::fuzz_image_decoder`]).
pub(crate) fn fuzz(data: &[u8]) {
    crate::texture_util::fuzz_image_decoder(data, "malformed KTX2 file", ktx2_size, decode_ktx2);
}

#[cfg(test)]
#[path = "ktx2_image_tests.rs"]
mod tests;
