//! DDS images (`MSFT_texture_dds`, or a DDS file wherever a PNG could be: a glTF `source`, an
//! MTL map): the block-compressed formats BC1 to BC7 and uncompressed 8-bit RGBA / BGRA, decoded
//! to RGBA8.
//!
//! The header (the legacy `DDS_HEADER` and, for FourCC `DX10`, the `DDS_HEADER_DXT10` that
//! follows it) is read and validated here; the texels are decoded by `image_dds` (pure Rust,
//! blocks by `bcdec_rs`), one level at a time, every level's bytes checked against the file's
//! length first. A panic of the decoder on corrupt data is caught and becomes this image's
//! one-line error, never a crash of the process. Before anything is decoded the texture's size
//! is checked against [`MAX_TEXTURE_SIZE`] and its decoded memory (every level it will decode)
//! charged to the load's budget.
//!
//! What is decoded, and how:
//! - BC1 (`DXT1`), BC2 (`DXT3`), BC3 (`DXT5`) and BC7, as RGBA; BC4 (`ATI1`, `BC4U`, `BC4S`) as
//!   grey (the one channel in red, green and blue, as a one-channel image reads in OpenGL's
//!   luminance swizzle, so that occlusion, read from red, and a grey base colour both work),
//!   BC5 (`ATI2`, `BC5U`, `BC5S`) as the two-channel normal map it is made for: red and green,
//!   and blue the Z those imply (`z = √(1 − x² − y²)` with `x`, `y` mapped from [0, 1] to
//!   [−1, 1], as engines reading BC5 normal maps rebuild it), unsigned BC6H clamped to [0, 1]
//!   and truncated to 8 bits (signed BC6H is refused: the decoder reads it as unsigned);
//! - 8-bit RGBA and BGRA, legacy (32-bit RGB masks) or DXGI, with alpha or without (`X8`
//!   formats and legacy files without an alpha mask are opaque); legacy 24-bit RGB and BGR
//!   (`D3DFMT_R8G8B8`, three bytes a texel, rows unpadded), opaque.
//!
//! Cube maps, volume textures and texture arrays are refused with one line naming what they
//! are, as are other formats (named by their FourCC, D3D or DXGI number) and premultiplied
//! `DXT2` / `DXT4`. Rows are stored top first, as glTF wants them.
//!
//! The texels' colour space is decided by the texture's use, as for every image; an `_SRGB`
//! DXGI format used for data (linear) gets a note. A file whose mip count covers the complete
//! chain (down to 1 × 1) and that holds the bytes of every level has every level decoded and
//! kept as stored ([`Texture::from_rgba8_levels`]); otherwise, or when a smaller level fails to
//! decode, level 0 is decoded and the texture builds its own chain ([`Texture::from_rgba8`]).

use image_dds::ImageFormat;
use kantele_rules::shade::texture::{ColorSpace, Texture, MAX_TEXTURE_SIZE};

use crate::budget::Budget;
use crate::texture_util::{ImageError, TEXTURE_BYTES_PER_TEXEL};

/// The 4 bytes a DDS file starts with.
const DDS_MAGIC: &[u8; 4] = b"DDS ";

/// The MIME type `MSFT_texture_dds` gives DDS images.
const DDS_MIME_TYPE: &str = "image/vnd-ms.dds";

/// Where the `DDS_HEADER_DXT10` starts, after the magic and the 124-byte `DDS_HEADER`; the
/// texels of a file without it start here too.
const DX10_HEADER_START: usize = 128;

/// Where the texels start in a file with a `DDS_HEADER_DXT10` (20 bytes).
const DX10_DATA_START: usize = DX10_HEADER_START + 20;

/// `DDS_HEADER.dwFlags`: the depth field is valid.
const DDSD_DEPTH: u32 = 0x80_0000;
/// `DDS_PIXELFORMAT.dwFlags`: the alpha mask is valid.
const DDPF_ALPHAPIXELS: u32 = 0x1;
/// `DDS_PIXELFORMAT.dwFlags`: the FourCC is valid.
const DDPF_FOURCC: u32 = 0x4;
/// `DDS_PIXELFORMAT.dwFlags`: uncompressed RGB texels described by masks.
const DDPF_RGB: u32 = 0x40;
/// `DDS_HEADER.dwCaps2`: the file is a cube map.
const DDSCAPS2_CUBEMAP: u32 = 0x200;
/// `DDS_HEADER.dwCaps2`: the file is a volume texture.
const DDSCAPS2_VOLUME: u32 = 0x20_0000;
/// `DDS_HEADER_DXT10.miscFlag`: the texture is a cube map.
const DDS_RESOURCE_MISC_TEXTURECUBE: u32 = 0x4;
/// `DDS_HEADER_DXT10.resourceDimension` of a 1D, a 2D and a 3D texture.
const DIMENSION_TEXTURE1D: u32 = 2;
const DIMENSION_TEXTURE2D: u32 = 3;
const DIMENSION_TEXTURE3D: u32 = 4;

/// Bytes per texel the decoder needs besides the RGBA8 it returns: its own RGBA8 buffer of the
/// level, copied into the one it returns.
const DECODER_SCRATCH_PER_TEXEL: u64 = 4;

/// Whether `bytes` are to be read as a DDS file: they start with `DDS `, or they are declared
/// `image/vnd-ms.dds` and are no other image format the loader knows (the data decides first,
/// as for the other formats: files often declare the wrong MIME type).
pub(crate) fn is_dds(bytes: &[u8], mime_type: Option<&str>) -> bool {
    bytes.starts_with(DDS_MAGIC)
        || (mime_type == Some(DDS_MIME_TYPE) && image::guess_format(bytes).is_err())
}

fn decode_error(message: impl Into<String>) -> ImageError {
    ImageError::Decode(message.into())
}

/// The texel format of a DDS file, as far as decoding is concerned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct TexelFormat {
    /// The decoder's format.
    format: ImageFormat,
    /// Whether alpha is not stored (`X8` formats, legacy files without an alpha mask): decoded
    /// texels get alpha 255.
    opaque: bool,
    /// Whether the format says its texels are sRGB-encoded (the `_SRGB` DXGI formats).
    declares_srgb: bool,
    /// Legacy 24-bit texels (three bytes each, decoded here, not by the decoder): where red,
    /// green and blue sit in each texel's bytes.
    packed24: Option<[usize; 3]>,
}

impl TexelFormat {
    fn new(format: ImageFormat) -> Self {
        Self {
            format,
            opaque: false,
            declares_srgb: false,
            packed24: None,
        }
    }

    fn srgb(format: ImageFormat) -> Self {
        Self {
            declares_srgb: true,
            ..Self::new(format)
        }
    }

    fn opaque(self) -> Self {
        Self {
            opaque: true,
            ..self
        }
    }

    /// Legacy 24-bit texels with red, green and blue at byte offsets `order` of each texel.
    fn packed24(order: [usize; 3]) -> Self {
        Self {
            packed24: Some(order),
            // Decoded here; the decoder's format only names it in messages.
            ..Self::new(ImageFormat::Rgba8Unorm).opaque()
        }
    }

    /// The format's name in messages: the decoder's, or "24-bit RGB" / "24-bit BGR" for the
    /// legacy 24-bit texels decoded here.
    fn name(self) -> String {
        match self.packed24 {
            Some([0, _, _]) => "24-bit RGB".to_string(),
            Some(_) => "24-bit BGR".to_string(),
            None => format!("{:?}", self.format),
        }
    }

    /// Bytes a `width` × `height` level takes in the file: whole 4 × 4 blocks for the BC
    /// formats, 4 bytes a texel for the uncompressed ones (3 for the 24-bit ones).
    fn level_bytes(self, width: u32, height: u32) -> u64 {
        let (w, h) = (u64::from(width), u64::from(height));
        let blocks = w.div_ceil(4) * h.div_ceil(4);
        if self.packed24.is_some() {
            return w * h * 3;
        }
        match self.format {
            ImageFormat::BC1RgbaUnorm
            | ImageFormat::BC1RgbaUnormSrgb
            | ImageFormat::BC4RUnorm
            | ImageFormat::BC4RSnorm => blocks * 8,
            ImageFormat::Rgba8Unorm
            | ImageFormat::Rgba8UnormSrgb
            | ImageFormat::Bgra8Unorm
            | ImageFormat::Bgra8UnormSrgb => w * h * 4,
            // BC2, BC3, BC5, unsigned BC6H, BC7 (`from_dxgi` and `from_legacy` make no others).
            _ => blocks * 16,
        }
    }

    /// The format of a `DDS_HEADER_DXT10`'s DXGI number (typeless formats are read as UNORM).
    fn from_dxgi(dxgi: u32) -> Result<Self, ImageError> {
        use ImageFormat as F;
        Ok(match dxgi {
            27 | 28 => Self::new(F::Rgba8Unorm),
            29 => Self::srgb(F::Rgba8UnormSrgb),
            70 | 71 => Self::new(F::BC1RgbaUnorm),
            72 => Self::srgb(F::BC1RgbaUnormSrgb),
            73 | 74 => Self::new(F::BC2RgbaUnorm),
            75 => Self::srgb(F::BC2RgbaUnormSrgb),
            76 | 77 => Self::new(F::BC3RgbaUnorm),
            78 => Self::srgb(F::BC3RgbaUnormSrgb),
            79 | 80 => Self::new(F::BC4RUnorm),
            81 => Self::new(F::BC4RSnorm),
            82 | 83 => Self::new(F::BC5RgUnorm),
            84 => Self::new(F::BC5RgSnorm),
            87 | 90 => Self::new(F::Bgra8Unorm),
            88 | 92 => Self::new(F::Bgra8Unorm).opaque(),
            91 => Self::srgb(F::Bgra8UnormSrgb),
            93 => Self::srgb(F::Bgra8UnormSrgb).opaque(),
            94 | 95 => Self::new(F::BC6hRgbUfloat),
            96 => {
                return Err(decode_error(
                    "DDS DXGI format 96 (BC6H_SF16, signed HDR) is not supported",
                ))
            }
            97 | 98 => Self::new(F::BC7RgbaUnorm),
            99 => Self::srgb(F::BC7RgbaUnormSrgb),
            other => {
                return Err(decode_error(format!(
                "DDS DXGI format {other} is not supported (BC1 to BC7 and 8-bit RGBA / BGRA are)"
            )))
            }
        })
    }

    /// The format of a legacy `DDS_PIXELFORMAT` (flags, FourCC, bits per texel, masks red,
    /// green, blue, alpha), without a `DDS_HEADER_DXT10`.
    fn from_legacy(
        flags: u32,
        four_cc: u32,
        bits: u32,
        masks: [u32; 4],
    ) -> Result<Self, ImageError> {
        use ImageFormat as F;
        if flags & DDPF_FOURCC != 0 {
            return Ok(match &four_cc.to_le_bytes() {
                b"DXT1" => Self::new(F::BC1RgbaUnorm),
                b"DXT3" => Self::new(F::BC2RgbaUnorm),
                b"DXT5" => Self::new(F::BC3RgbaUnorm),
                b"ATI1" | b"BC4U" => Self::new(F::BC4RUnorm),
                b"BC4S" => Self::new(F::BC4RSnorm),
                b"ATI2" | b"BC5U" => Self::new(F::BC5RgUnorm),
                b"BC5S" => Self::new(F::BC5RgSnorm),
                b"DXT2" | b"DXT4" => {
                    return Err(decode_error(format!(
                        "DDS FourCC {} (premultiplied alpha) is not supported",
                        four_cc_name(four_cc)
                    )))
                }
                _ => {
                    return Err(decode_error(format!(
                        "DDS {} is not supported (BC1 to BC7 and 8-bit RGBA / BGRA are)",
                        four_cc_name(four_cc)
                    )))
                }
            });
        }
        let [red, green, blue, alpha] = masks;
        if flags & DDPF_RGB != 0 && bits == 24 {
            match (red, green, blue) {
                (0xff_0000, 0xff00, 0xff) => return Ok(Self::packed24([2, 1, 0])),
                (0xff, 0xff00, 0xff_0000) => return Ok(Self::packed24([0, 1, 2])),
                _ => {}
            }
        }
        if flags & DDPF_RGB != 0 && bits == 32 {
            let format = match (red, green, blue) {
                (0xff, 0xff00, 0xff_0000) => Some(F::Rgba8Unorm),
                (0xff_0000, 0xff00, 0xff) => Some(F::Bgra8Unorm),
                _ => None,
            };
            if let Some(format) = format {
                let with_alpha = flags & DDPF_ALPHAPIXELS != 0 && alpha == 0xff00_0000;
                let texels = Self::new(format);
                return Ok(if with_alpha { texels } else { texels.opaque() });
            }
        }
        Err(decode_error(format!(
            "DDS uncompressed texels of {bits} bits (flags {flags:#x}, masks R {red:#x} G {green:#x} B {blue:#x} A {alpha:#x}) are not supported (8-bit RGBA / BGRA and 24-bit RGB / BGR are)"
        )))
    }
}

/// A FourCC in words: its four characters when they are printable, else the D3D format number
/// legacy files store there.
fn four_cc_name(four_cc: u32) -> String {
    let bytes = four_cc.to_le_bytes();
    if bytes.iter().all(|b| b.is_ascii_graphic() || *b == b' ') {
        format!("FourCC '{}'", String::from_utf8_lossy(&bytes))
    } else {
        format!("D3D format {four_cc}")
    }
}

/// A validated DDS file: its header facts and texels, ready to decode.
struct DdsFile<'a> {
    width: u32,
    height: u32,
    /// Levels the header declares (at least 1).
    mip_count: u32,
    texels: TexelFormat,
    /// Everything after the headers: the levels, level 0 first.
    data: &'a [u8],
}

impl<'a> DdsFile<'a> {
    /// Parses and validates the headers; an error for everything this loader does not decode
    /// (cube maps, volume textures, arrays, other formats: the message names them) and for a
    /// file too short to hold level 0.
    fn parse(bytes: &'a [u8]) -> Result<Self, ImageError> {
        if !bytes.starts_with(DDS_MAGIC) {
            return Err(decode_error(
                "not a DDS file (it does not start with 'DDS ')",
            ));
        }
        let word = |at: usize| {
            bytes
                .get(at..at + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        let truncated = |needed: usize| {
            decode_error(format!(
                "the DDS file is truncated: {} bytes, its header needs {needed}",
                bytes.len()
            ))
        };
        let header = |at: usize| word(at).ok_or_else(|| truncated(DX10_HEADER_START));
        if header(4)? != 124 || header(76)? != 32 {
            return Err(decode_error(format!(
                "not a valid DDS file: header size {} and pixel format size {} (124 and 32 expected)",
                header(4)?,
                header(76)?
            )));
        }
        let (flags, height, width, depth) = (header(8)?, header(12)?, header(16)?, header(24)?);
        let mip_count = header(28)?.max(1);
        let (format_flags, four_cc, bits) = (header(80)?, header(84)?, header(88)?);
        let masks = [header(92)?, header(96)?, header(100)?, header(104)?];
        let caps2 = header(112)?;
        if caps2 & DDSCAPS2_CUBEMAP != 0 {
            return Err(decode_error("the DDS file is a cube map"));
        }
        if caps2 & DDSCAPS2_VOLUME != 0 || (flags & DDSD_DEPTH != 0 && depth > 1) {
            return Err(decode_error("the DDS file is a volume (3D) texture"));
        }
        let dx10 = format_flags & DDPF_FOURCC != 0 && &four_cc.to_le_bytes() == b"DX10";
        let (texels, data_start) = if dx10 {
            let dx10_header =
                |at: usize| word(DX10_HEADER_START + at).ok_or_else(|| truncated(DX10_DATA_START));
            let (dxgi, dimension) = (dx10_header(0)?, dx10_header(4)?);
            let (misc, array_size) = (dx10_header(8)?, dx10_header(12)?);
            if misc & DDS_RESOURCE_MISC_TEXTURECUBE != 0 {
                return Err(decode_error("the DDS file is a cube map"));
            }
            match dimension {
                DIMENSION_TEXTURE1D | DIMENSION_TEXTURE2D => {}
                DIMENSION_TEXTURE3D => {
                    return Err(decode_error("the DDS file is a volume (3D) texture"))
                }
                other => {
                    return Err(decode_error(format!(
                        "not a valid DDS file: resource dimension {other}"
                    )))
                }
            }
            if array_size != 1 {
                return Err(decode_error(format!(
                    "the DDS file is an array of {array_size} textures"
                )));
            }
            (TexelFormat::from_dxgi(dxgi)?, DX10_DATA_START)
        } else {
            let texels = TexelFormat::from_legacy(format_flags, four_cc, bits, masks)?;
            (texels, DX10_HEADER_START)
        };
        if width == 0 || height == 0 || width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
            return Err(decode_error(format!(
                "DDS image size {width}x{height} is outside 1..={MAX_TEXTURE_SIZE}"
            )));
        }
        let data = bytes.get(data_start..).unwrap_or_default();
        let file = Self {
            width,
            height,
            mip_count,
            texels,
            data,
        };
        let needed = texels.level_bytes(width, height);
        if (data.len() as u64) < needed {
            return Err(decode_error(format!(
                "the DDS file is truncated: it holds {} bytes of texels, but a {width}x{height} {} image needs {needed}",
                data.len(),
                texels.name()
            )));
        }
        Ok(file)
    }

    /// The size of level `index` in texels: `max(1, width >> index)` × `max(1, height >>
    /// index)`.
    fn level_dimensions(&self, index: u32) -> (u32, u32) {
        let halve = |size: u32| size.checked_shr(index).unwrap_or(0).max(1);
        (halve(self.width), halve(self.height))
    }

    /// Level `index`'s stored bytes (`None` when the file is too short for them).
    fn level_data(&self, index: u32) -> Option<&'a [u8]> {
        let start: u64 = (0..index)
            .map(|i| {
                let (w, h) = self.level_dimensions(i);
                self.texels.level_bytes(w, h)
            })
            .sum();
        let (w, h) = self.level_dimensions(index);
        let end = start + self.texels.level_bytes(w, h);
        self.data
            .get(usize::try_from(start).ok()?..usize::try_from(end).ok()?)
    }

    /// How many levels the file's complete mip chain has, when it holds one (its mip count
    /// covers every level down to 1 × 1 and the file holds their bytes); `None` otherwise.
    fn complete_chain(&self) -> Option<u32> {
        let full = 32 - self.width.max(self.height).leading_zeros();
        (full > 1 && self.mip_count == full && self.level_data(full - 1).is_some()).then_some(full)
    }

    /// Level `index` as RGBA8, rows top first.
    fn decode_level(&self, index: u32) -> Result<Vec<u8>, ImageError> {
        let (width, height) = self.level_dimensions(index);
        let data = self
            .level_data(index)
            .ok_or_else(|| decode_error(format!("the DDS file is truncated in level {index}")))?;
        if let Some([r, g, b]) = self.texels.packed24 {
            // `level_data` holds exactly the level's 3 bytes a texel.
            return Ok(data
                .chunks_exact(3)
                .flat_map(|t| [t[r], t[g], t[b], 255])
                .collect());
        }
        let surface = image_dds::Surface {
            width,
            height,
            depth: 1,
            layers: 1,
            mipmaps: 1,
            image_format: self.texels.format,
            data,
        };
        let mut rgba = caught(|| surface.decode_rgba8())?
            .map_err(|e| decode_error(format!("cannot decode DDS level {index}: {e}")))?
            .data;
        if rgba.len() != width as usize * height as usize * 4 {
            return Err(decode_error(format!(
                "the DDS decoder gave {} bytes for a {width}x{height} image",
                rgba.len()
            )));
        }
        if self.texels.opaque {
            for texel in rgba.chunks_exact_mut(4) {
                texel[3] = 255;
            }
        }
        if matches!(
            self.texels.format,
            ImageFormat::BC5RgUnorm | ImageFormat::BC5RgSnorm
        ) {
            for texel in rgba.chunks_exact_mut(4) {
                texel[2] = normal_z(texel[0], texel[1]);
            }
        }
        Ok(rgba)
    }
}

/// The Z byte of a unit normal whose X and Y bytes are `x` and `y` (each mapped from [0, 255]
/// to [−1, 1]): `√(1 − x² − y²)` (0 where X and Y alone are longer than 1), mapped back and
/// rounded.
fn normal_z(x: u8, y: u8) -> u8 {
    let signed = |byte: u8| f32::from(byte) / 255.0 * 2.0 - 1.0;
    let (x, y) = (signed(x), signed(y));
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    ((z * 0.5 + 0.5) * 255.0).round() as u8
}

/// Runs the decoder with its panics caught: a known way such code fails on corrupt data,
/// turned into a one-line error for this image instead of a failed load.
fn caught<T>(f: impl FnOnce() -> T) -> Result<T, ImageError> {
    crate::quiet_panic::catch(f)
        .map_err(|m| decode_error(format!("malformed DDS file (the decoder failed: {m})")))
}

/// The size of a DDS image from its header (nothing is decoded).
pub(crate) fn dds_size(bytes: &[u8]) -> Result<(u32, u32), ImageError> {
    let file = DdsFile::parse(bytes)?;
    Ok((file.width, file.height))
}

/// Decodes a DDS image into a texture whose texels are encoded in `color_space` (decided by the
/// texture's use, as for every image), after charging the texture's memory and the decoder's
/// to `budget`: with the file's own mip levels when it holds the complete chain, else level 0
/// with a chain the texture builds.
pub(crate) fn decode_dds(
    bytes: &[u8],
    color_space: ColorSpace,
    budget: &mut Budget,
) -> Result<Texture, ImageError> {
    let file = DdsFile::parse(bytes)?;
    let (width, height) = (file.width, file.height);
    let chain = file.complete_chain();
    // The decoded RGBA8 of every level read (4 bytes a texel, 4/3 of that with the smaller
    // levels, rounded up), besides the texture and the decoder's scratch.
    let decoded_per_texel = if chain.is_some() { 6 } else { 4 };
    budget
        .charge(
            u64::from(width) * u64::from(height),
            TEXTURE_BYTES_PER_TEXEL + decoded_per_texel + DECODER_SCRATCH_PER_TEXEL,
            &format!("a {width}x{height} DDS texture"),
        )
        .map_err(ImageError::Budget)?;
    let level0 = file.decode_level(0)?;
    let smaller: Option<Vec<Vec<u8>>> =
        chain.and_then(|count| (1..count).map(|i| file.decode_level(i).ok()).collect());
    if let Some(smaller) = smaller {
        let levels: Vec<&[u8]> = std::iter::once(&level0[..])
            .chain(smaller.iter().map(Vec::as_slice))
            .collect();
        // Checked level by level above; a chain the texture still refuses falls back too.
        if let Ok(texture) = Texture::from_rgba8_levels(width, height, &levels, color_space) {
            return Ok(texture);
        }
    }
    Texture::from_rgba8(width, height, &level0, color_space)
        .map_err(|e| ImageError::Decode(e.to_string()))
}

/// A note when a DDS image declares sRGB texels (an `_SRGB` DXGI format) but its use makes them
/// linear; `None` for other images and when they agree. (UNORM formats are not taken as a
/// declaration of linear texels: DDS tools write them for colour textures too.)
pub(crate) fn color_space_note(bytes: &[u8], color_space: ColorSpace) -> Option<String> {
    if !bytes.starts_with(DDS_MAGIC) || color_space != ColorSpace::Linear {
        return None;
    }
    DdsFile::parse(bytes).ok()?.texels.declares_srgb.then(|| {
        "the DDS file declares sRGB texels, but the texture's use makes them linear; read as linear"
            .to_string()
    })
}

/// Body of the `dds` fuzz target ([`crate::texture_util::fuzz_image_decoder`]).
pub(crate) fn fuzz(data: &[u8]) {
    crate::texture_util::fuzz_image_decoder(data, "malformed DDS file", dds_size, decode_dds);
}

#[cfg(test)]
mod tests {
    //! DDS files written here, header field by header field: uncompressed RGBA / BGRA (legacy
    //! masks and DXGI), BC1 blocks of known colours, mip chains, and broken or hostile files;
    //! then DDS images loaded through glTF's `MSFT_texture_dds` and an MTL map.

    use super::*;

    /// How a test file describes its texels.
    #[derive(Clone, Copy)]
    enum Pixels {
        /// A legacy FourCC.
        FourCc(&'static [u8; 4]),
        /// Legacy uncompressed texels: bits per texel and masks red, green, blue, alpha (alpha
        /// 0: no `DDPF_ALPHAPIXELS`).
        Masks(u32, [u32; 4]),
        /// A `DDS_HEADER_DXT10` with this DXGI format, a 2D texture, no flags, one layer.
        Dxgi(u32),
    }

    const RGBA_MASKS: [u32; 4] = [0xff, 0xff00, 0xff_0000, 0xff00_0000];
    const BGRA_MASKS: [u32; 4] = [0xff_0000, 0xff00, 0xff, 0xff00_0000];

    /// Offsets of header fields (from the file's start) that tests patch.
    const CAPS2_AT: usize = 112;
    const DX10_MISC_AT: usize = 136;
    const DX10_ARRAY_AT: usize = 140;

    /// A DDS file of `width` × `height` with `mip_count` in its header, `pixels` and `texels`
    /// (every level, level 0 first).
    fn dds(width: u32, height: u32, mip_count: u32, pixels: Pixels, texels: &[u8]) -> Vec<u8> {
        // DDSD_CAPS | DDSD_HEIGHT | DDSD_WIDTH | DDSD_PIXELFORMAT, and DDSD_MIPMAPCOUNT.
        let flags = 0x1007 | if mip_count > 1 { 0x2_0000 } else { 0 };
        let (format_flags, four_cc, bits, masks) = match pixels {
            Pixels::FourCc(code) => (DDPF_FOURCC, u32::from_le_bytes(*code), 0, [0; 4]),
            Pixels::Masks(bits, masks) => {
                let alpha = if masks[3] != 0 { DDPF_ALPHAPIXELS } else { 0 };
                (DDPF_RGB | alpha, 0, bits, masks)
            }
            Pixels::Dxgi(_) => (DDPF_FOURCC, u32::from_le_bytes(*b"DX10"), 0, [0; 4]),
        };
        let mut words = vec![124, flags, height, width, 0, 0, mip_count];
        words.extend([0; 11]);
        words.extend([32, format_flags, four_cc, bits]);
        words.extend(masks);
        // DDSCAPS_TEXTURE (and DDSCAPS_COMPLEX | DDSCAPS_MIPMAP); caps2 to caps4, reserved.
        words.push(0x1000 | if mip_count > 1 { 0x40_0008 } else { 0 });
        words.extend([0; 4]);
        if let Pixels::Dxgi(format) = pixels {
            words.extend([format, DIMENSION_TEXTURE2D, 0, 1, 0]);
        }
        let mut out = DDS_MAGIC.to_vec();
        for word in words {
            out.extend_from_slice(&word.to_le_bytes());
        }
        out.extend_from_slice(texels);
        out
    }

    /// Writes `value` at byte `at` of a copy of `bytes`.
    fn patched(bytes: &[u8], at: usize, value: u32) -> Vec<u8> {
        let mut out = bytes.to_vec();
        out[at..at + 4].copy_from_slice(&value.to_le_bytes());
        out
    }

    fn decode(bytes: &[u8], color_space: ColorSpace) -> Result<Texture, String> {
        let mut budget = Budget::new(crate::DEFAULT_MAX_MEMORY);
        decode_dds(bytes, color_space, &mut budget).map_err(|e| match e {
            ImageError::Budget(m) | ImageError::Decode(m) => m,
        })
    }

    /// Every texel of level `index`, as RGBA bytes, row by row.
    fn level_texels(texture: &Texture, index: usize) -> Vec<[u8; 4]> {
        let level = texture.level(index).expect("level");
        level.texels.iter().map(|t| t.to_le_bytes()).collect()
    }

    /// A 2 × 2 picture, top row first: four colours, alphas 255, 128, 64, 0.
    const PICTURE: [[u8; 4]; 4] = [
        [250, 10, 20, 255],
        [30, 240, 40, 128],
        [50, 60, 230, 64],
        [200, 190, 180, 0],
    ];

    #[test]
    fn uncompressed_rgba_and_bgra_decode_exactly() {
        let rgba = PICTURE.concat();
        let bgra: Vec<u8> = PICTURE
            .iter()
            .flat_map(|&[r, g, b, a]| [b, g, r, a])
            .collect();
        let opaque = PICTURE.map(|[r, g, b, _]| [r, g, b, 255]).to_vec();
        let bgr: Vec<u8> = PICTURE.iter().flat_map(|&[r, g, b, _]| [b, g, r]).collect();
        let rgb: Vec<u8> = PICTURE.iter().flat_map(|&[r, g, b, _]| [r, g, b]).collect();
        let cases = [
            (
                "legacy 24-bit BGR",
                dds(
                    2,
                    2,
                    1,
                    Pixels::Masks(24, [0xff_0000, 0xff00, 0xff, 0]),
                    &bgr,
                ),
                opaque.clone(),
            ),
            (
                "legacy 24-bit RGB",
                dds(
                    2,
                    2,
                    1,
                    Pixels::Masks(24, [0xff, 0xff00, 0xff_0000, 0]),
                    &rgb,
                ),
                opaque.clone(),
            ),
            (
                "legacy RGBA",
                dds(2, 2, 1, Pixels::Masks(32, RGBA_MASKS), &rgba),
                PICTURE.to_vec(),
            ),
            (
                "legacy BGRA",
                dds(2, 2, 1, Pixels::Masks(32, BGRA_MASKS), &bgra),
                PICTURE.to_vec(),
            ),
            (
                "legacy BGRX",
                dds(
                    2,
                    2,
                    1,
                    Pixels::Masks(32, [0xff_0000, 0xff00, 0xff, 0]),
                    &bgra,
                ),
                opaque.clone(),
            ),
            (
                "DXGI R8G8B8A8_UNORM",
                dds(2, 2, 1, Pixels::Dxgi(28), &rgba),
                PICTURE.to_vec(),
            ),
            (
                "DXGI R8G8B8A8_UNORM_SRGB",
                dds(2, 2, 1, Pixels::Dxgi(29), &rgba),
                PICTURE.to_vec(),
            ),
            (
                "DXGI B8G8R8A8_UNORM",
                dds(2, 2, 1, Pixels::Dxgi(87), &bgra),
                PICTURE.to_vec(),
            ),
            (
                "DXGI B8G8R8X8_UNORM",
                dds(2, 2, 1, Pixels::Dxgi(88), &bgra),
                opaque,
            ),
        ];
        for (name, file, expected) in cases {
            assert_eq!(dds_size(&file).unwrap(), (2, 2), "{name}");
            for color_space in [ColorSpace::Srgb, ColorSpace::Linear] {
                let texture = decode(&file, color_space).unwrap_or_else(|e| panic!("{name}: {e}"));
                assert_eq!(texture.source_color_space(), color_space, "{name}");
                assert_eq!(texture.level_count(), 2, "{name}");
                assert_eq!(level_texels(&texture, 0), expected, "{name}");
            }
        }
    }

    /// A 24-bit file's rows are three bytes a texel, unpadded, level after level: a file of
    /// three levels one byte short of the last is read from level 0 alone, one short of level 0
    /// is refused naming its layout.
    #[test]
    fn a_24_bit_chain_is_read_level_by_level() {
        let level = |[r, g, b]: [u8; 3], texels: usize| [b, g, r].repeat(texels);
        // 4 × 3, 2 × 1, 1 × 1.
        let chain = [
            level([200, 10, 0], 12),
            level([0, 200, 10], 2),
            level([5, 6, 7], 1),
        ];
        let masks = [0xff_0000, 0xff00, 0xff, 0];
        let file = dds(4, 3, 3, Pixels::Masks(24, masks), &chain.concat());
        let texture = decode(&file, ColorSpace::Linear).expect("a 24-bit chain");
        assert_eq!(level_texels(&texture, 1), vec![[0, 200, 10, 255]; 2]);
        assert_eq!(level_texels(&texture, 2), vec![[5, 6, 7, 255]]);
        let short = &file[..file.len() - 1];
        let texture = decode(short, ColorSpace::Linear).expect("level 0 alone");
        assert_eq!(level_texels(&texture, 0), vec![[200, 10, 0, 255]; 12]);
        // Short of level 0: the message names the layout the file declares.
        let e = decode(&file[..file.len() - 20], ColorSpace::Linear).unwrap_err();
        assert!(
            e.contains("truncated") && e.contains("4x3 24-bit BGR"),
            "{e}"
        );
        // Other 24-bit layouts are refused, naming what is read.
        let other = dds(
            4,
            3,
            1,
            Pixels::Masks(24, [0xff00, 0xff, 0xff_0000, 0]),
            &chain[0],
        );
        let e = decode(&other, ColorSpace::Linear).unwrap_err();
        assert!(
            e.contains("24 bits") && e.contains("24-bit RGB / BGR are"),
            "{e}"
        );
    }

    /// BC5 holds a normal map's X and Y: Z is rebuilt from them, the normal's length 1.
    #[test]
    fn bc5_normal_maps_get_their_z() {
        // One BC5 block per channel pair: endpoints (r0, r1) with every index 0 (texel = r0).
        let channel = |value: u8| [value, 0, 0, 0, 0, 0, 0, 0];
        for (x, y) in [(128u8, 128u8), (255, 128), (180, 60), (0, 0)] {
            let block = [channel(x), channel(y)].concat();
            for code in [b"ATI2", b"BC5U"] {
                let file = dds(4, 4, 1, Pixels::FourCc(code), &block);
                let texture = decode(&file, ColorSpace::Linear).expect("BC5");
                let [r, g, b, a] = level_texels(&texture, 0)[5];
                assert_eq!([r, g, a], [x, y, 255]);
                let unit = |v: u8| f32::from(v) / 255.0 * 2.0 - 1.0;
                let length2 = unit(r).powi(2) + unit(g).powi(2) + unit(b).powi(2);
                if length2 > 1.0 + 0.02 {
                    // X and Y alone longer than 1: Z is 0 (the middle byte).
                    assert!(
                        unit(r).powi(2) + unit(g).powi(2) > 1.0 && b == 128,
                        "{x} {y}: {b}"
                    );
                } else {
                    assert!(
                        (length2 - 1.0).abs() < 0.02,
                        "{x} {y}: z {b}, |n|² {length2}"
                    );
                }
            }
        }
        assert_eq!(normal_z(128, 128), 255);
    }

    #[test]
    fn an_srgb_format_used_for_data_gets_a_note() {
        let rgba = PICTURE.concat();
        let srgb = dds(2, 2, 1, Pixels::Dxgi(29), &rgba);
        assert_eq!(color_space_note(&srgb, ColorSpace::Srgb), None);
        let note = color_space_note(&srgb, ColorSpace::Linear).unwrap();
        assert!(
            note.contains("declares sRGB") && note.contains("read as linear"),
            "{note}"
        );
        // UNORM and legacy formats declare nothing.
        let unorm = dds(2, 2, 1, Pixels::Dxgi(28), &rgba);
        let legacy = dds(2, 2, 1, Pixels::Masks(32, RGBA_MASKS), &rgba);
        for file in [unorm, legacy] {
            assert_eq!(color_space_note(&file, ColorSpace::Linear), None);
            assert_eq!(color_space_note(&file, ColorSpace::Srgb), None);
        }
    }

    /// A BC1 block: colours red (565 0xF800) and green (0x07E0) in four-colour mode, with the
    /// indices of texels 0 to 15 (row by row).
    fn bc1_block(color0: u16, color1: u16, indices: [u32; 16]) -> [u8; 8] {
        let bits = indices
            .iter()
            .enumerate()
            .fold(0u32, |bits, (i, &index)| bits | index << (2 * i));
        let mut block = [0; 8];
        block[..2].copy_from_slice(&color0.to_le_bytes());
        block[2..4].copy_from_slice(&color1.to_le_bytes());
        block[4..].copy_from_slice(&bits.to_le_bytes());
        block
    }

    const RED_565: u16 = 0xf800;
    const GREEN_565: u16 = 0x07e0;
    /// Row by row, the indices 0, 1, 2, 3 in every order the test checks.
    const INDICES: [u32; 16] = [0, 1, 2, 3, 3, 2, 1, 0, 0, 0, 1, 1, 2, 2, 3, 3];

    #[test]
    fn a_bc1_block_decodes_to_its_colours() {
        // Four-colour mode (color0 > color1): red, green, 2/3 red + 1/3 green, 1/3 red + 2/3
        // green, each channel rounded to the nearest byte.
        let palette = [
            [255, 0, 0, 255],
            [0, 255, 0, 255],
            [170, 85, 0, 255],
            [85, 170, 0, 255],
        ];
        let block = bc1_block(RED_565, GREEN_565, INDICES);
        let expected: Vec<[u8; 4]> = INDICES.iter().map(|&i| palette[i as usize]).collect();
        for file in [
            dds(4, 4, 1, Pixels::FourCc(b"DXT1"), &block),
            dds(4, 4, 1, Pixels::Dxgi(71), &block),
            dds(4, 4, 1, Pixels::Dxgi(72), &block),
        ] {
            let texture = decode(&file, ColorSpace::Srgb).unwrap();
            assert_eq!(level_texels(&texture, 0), expected);
        }
        // Three-colour mode (color0 <= color1): index 2 is the half-way colour, 3 is
        // transparent black.
        let block = bc1_block(GREEN_565, RED_565, INDICES);
        let palette = [
            [0, 255, 0, 255],
            [255, 0, 0, 255],
            [128, 128, 0, 255],
            [0, 0, 0, 0],
        ];
        let texture = decode(
            &dds(4, 4, 1, Pixels::FourCc(b"DXT1"), &block),
            ColorSpace::Srgb,
        )
        .unwrap();
        let expected: Vec<[u8; 4]> = INDICES.iter().map(|&i| palette[i as usize]).collect();
        assert_eq!(level_texels(&texture, 0), expected);
        // A 3 × 2 image is the top-left corner of its one block.
        let block = bc1_block(RED_565, GREEN_565, INDICES);
        let texture = decode(
            &dds(3, 2, 1, Pixels::FourCc(b"DXT1"), &block),
            ColorSpace::Srgb,
        )
        .unwrap();
        let corner: Vec<[u8; 4]> = [0, 1, 2, 4, 5, 6]
            .iter()
            .map(|&t| {
                [
                    [255, 0, 0, 255],
                    [0, 255, 0, 255],
                    [170, 85, 0, 255],
                    [85, 170, 0, 255],
                ][INDICES[t] as usize]
            })
            .collect();
        assert_eq!(level_texels(&texture, 0), corner);
    }

    const RED: [u8; 4] = [200, 0, 0, 255];
    const GREEN: [u8; 4] = [0, 180, 0, 255];
    const BLUE: [u8; 4] = [0, 0, 160, 128];

    /// `width` × `height` texels all of `colour`.
    fn flat(width: u32, height: u32, colour: [u8; 4]) -> Vec<u8> {
        colour.repeat(width as usize * height as usize)
    }

    #[test]
    fn a_complete_mip_chain_is_taken_from_the_file() {
        let chain = [flat(4, 2, RED), flat(2, 1, GREEN), flat(1, 1, BLUE)].concat();
        let file = dds(4, 2, 3, Pixels::Masks(32, RGBA_MASKS), &chain);
        let texture = decode(&file, ColorSpace::Srgb).unwrap();
        assert_eq!(texture.level_count(), 3);
        // The file's levels as they are, not averages of level 0 (which would stay red).
        assert_eq!(level_texels(&texture, 0), vec![RED; 8]);
        assert_eq!(level_texels(&texture, 1), vec![GREEN; 2]);
        assert_eq!(level_texels(&texture, 2), vec![BLUE]);
        // BC1: an 8 × 8 image with four levels of one block each... of the right colours.
        let solid = |c: u16| bc1_block(c, c, [0; 16]);
        let blocks = [
            [solid(RED_565); 4].concat(),
            solid(GREEN_565).to_vec(),
            solid(0x001f).to_vec(),
            solid(RED_565).to_vec(),
        ]
        .concat();
        let texture = decode(
            &dds(8, 8, 4, Pixels::FourCc(b"DXT1"), &blocks),
            ColorSpace::Linear,
        )
        .unwrap();
        assert_eq!(level_texels(&texture, 1), vec![[0, 255, 0, 255]; 16]);
        assert_eq!(level_texels(&texture, 2), vec![[0, 0, 255, 255]; 4]);
        assert_eq!(level_texels(&texture, 3), vec![[255, 0, 0, 255]]);
    }

    #[test]
    fn an_incomplete_chain_falls_back_to_level_0() {
        let built = |texture: &Texture| {
            assert_eq!(texture.level_count(), 3);
            assert_eq!(level_texels(texture, 0), vec![RED; 8]);
            // Built from level 0: red again.
            assert_eq!(level_texels(texture, 1), vec![RED; 2]);
            assert_eq!(level_texels(texture, 2), vec![RED]);
        };
        let chain = [flat(4, 2, RED), flat(2, 1, GREEN), flat(1, 1, BLUE)].concat();
        // Two levels declared of three; the bytes of the last level missing; a count past the
        // chain.
        for (mip_count, bytes) in [(2, chain.len()), (3, chain.len() - 4), (4, chain.len())] {
            let file = dds(
                4,
                2,
                mip_count,
                Pixels::Masks(32, RGBA_MASKS),
                &chain[..bytes],
            );
            built(&decode(&file, ColorSpace::Srgb).unwrap());
        }
    }

    #[test]
    fn broken_and_hostile_files_give_one_line_errors() {
        let block = bc1_block(RED_565, GREEN_565, INDICES);
        let rgba = PICTURE.concat();
        let files = [
            dds(4, 4, 1, Pixels::FourCc(b"DXT1"), &block),
            dds(2, 2, 1, Pixels::Dxgi(29), &rgba),
            dds(2, 2, 1, Pixels::Masks(32, BGRA_MASKS), &rgba),
        ];
        for file in &files {
            // Truncated at every length short of the whole file.
            for len in 0..file.len() {
                match decode(&file[..len], ColorSpace::Srgb) {
                    Err(e) => assert!(!e.contains('\n') && !e.is_empty(), "[..{len}]: {e}"),
                    Ok(_) => panic!("truncated to {len} bytes decoded"),
                }
            }
        }
        let e = decode(&files[0][..100], ColorSpace::Srgb).unwrap_err();
        assert!(e.contains("truncated") && e.contains("100 bytes"), "{e}");
        let e = decode(&files[0][..130], ColorSpace::Srgb).unwrap_err();
        assert!(
            e.contains("holds 2 bytes of texels") && e.contains("needs 8"),
            "{e}"
        );
        // A huge declared size: refused from the header, nothing allocated.
        let huge = patched(&patched(&files[0], 12, 100_000), 16, 100_000);
        let e = decode(&huge, ColorSpace::Srgb).unwrap_err();
        assert!(e.contains("100000x100000") && e.contains("outside"), "{e}");
        assert!(dds_size(&huge).is_err());
        // The largest size the limit allows, but not its bytes.
        let big = patched(&patched(&files[0], 12, 16384), 16, 16384);
        assert!(decode(&big, ColorSpace::Srgb)
            .unwrap_err()
            .contains("truncated"));
        // Cube maps, volumes, arrays, by either header.
        let refusals = [
            (patched(&files[0], CAPS2_AT, 0xfe00), "cube map"),
            (
                patched(&files[1], DX10_MISC_AT, DDS_RESOURCE_MISC_TEXTURECUBE),
                "cube map",
            ),
            (patched(&files[0], CAPS2_AT, DDSCAPS2_VOLUME), "volume"),
            (patched(&files[1], 132, DIMENSION_TEXTURE3D), "volume"),
            (patched(&files[1], DX10_ARRAY_AT, 6), "array of 6 textures"),
            (patched(&files[1], DX10_ARRAY_AT, 0), "array of 0 textures"),
            (
                dds(4, 4, 1, Pixels::FourCc(b"DXT2"), &block),
                "premultiplied",
            ),
            (dds(2, 2, 1, Pixels::Dxgi(10), &[0; 32]), "DXGI format 10"),
            (dds(4, 4, 1, Pixels::Dxgi(96), &[0; 16]), "BC6H_SF16"),
            (
                dds(2, 2, 1, Pixels::FourCc(&[113, 0, 0, 0]), &[0; 32]),
                "D3D format 113",
            ),
            (
                dds(2, 2, 1, Pixels::FourCc(b"ETC1"), &[0; 8]),
                "FourCC 'ETC1'",
            ),
            (
                dds(
                    2,
                    2,
                    1,
                    Pixels::Masks(16, [0xf800, 0x7e0, 0x1f, 0]),
                    &[0; 8],
                ),
                "16 bits",
            ),
            (patched(&files[0], 4, 100), "header size 100"),
        ];
        for (file, reason) in refusals {
            let e = decode(&file, ColorSpace::Srgb).unwrap_err();
            assert!(e.contains(reason) && !e.contains('\n'), "{reason}: {e}");
        }
    }

    #[test]
    fn the_budget_pays_for_every_level_before_decoding() {
        // 1024 × 1024 BC1: 512 KiB in the file, about 30 MiB once decoded with its chain.
        let blocks = vec![0u8; 512 * 1024];
        let file = dds(1024, 1024, 1, Pixels::FourCc(b"DXT1"), &blocks);
        let mut budget = Budget::new(16 << 20);
        match decode_dds(&file, ColorSpace::Srgb, &mut budget) {
            Err(ImageError::Budget(e)) => assert!(e.contains("1024x1024 DDS texture"), "{e}"),
            other => panic!("not a budget error: {other:?}"),
        }
        // A file's own chain costs more than level 0 alone, charged before decoding.
        let chain = [flat(4, 2, RED), flat(2, 1, GREEN), flat(1, 1, BLUE)].concat();
        let one = dds(4, 2, 1, Pixels::Masks(32, RGBA_MASKS), &chain[..32]);
        let three = dds(4, 2, 3, Pixels::Masks(32, RGBA_MASKS), &chain);
        let level0_charge = 8 * (TEXTURE_BYTES_PER_TEXEL + 4 + DECODER_SCRATCH_PER_TEXEL);
        let mut budget = Budget::new(level0_charge);
        decode_dds(&one, ColorSpace::Srgb, &mut budget).expect("level 0 fits");
        let mut budget = Budget::new(level0_charge);
        assert!(matches!(
            decode_dds(&three, ColorSpace::Srgb, &mut budget),
            Err(ImageError::Budget(_))
        ));
    }

    #[test]
    fn dds_is_recognised_by_its_identifier_or_declared_type() {
        let file = dds(2, 2, 1, Pixels::Dxgi(28), &PICTURE.concat());
        assert!(is_dds(&file, None));
        assert!(is_dds(b"garbage", Some("image/vnd-ms.dds")));
        assert!(!is_dds(b"garbage", Some("image/png")));
        // Data in another known format wins over a wrong declaration.
        assert!(!is_dds(b"\x89PNG\r\n\x1a\n rest", Some("image/vnd-ms.dds")));
        // Through the loader's image functions, by the data alone.
        assert_eq!(
            crate::texture_util::image_size(&file, None).unwrap(),
            (2, 2)
        );
        let mut budget = Budget::new(1 << 20);
        let texture =
            crate::texture_util::decode_within(&file, None, ColorSpace::Srgb, &mut budget).unwrap();
        assert_eq!(level_texels(&texture, 0), PICTURE.to_vec());
        // Declared DDS but not one: a DDS error, not an image-crate one.
        let e = match crate::texture_util::decode_within(
            b"garbage",
            Some("image/vnd-ms.dds"),
            ColorSpace::Srgb,
            &mut budget,
        ) {
            Err(ImageError::Decode(e)) => e,
            other => panic!("{other:?}"),
        };
        assert!(e.contains("not a DDS file"), "{e}");
    }

    /// The files of `tests/data/dds` (seeds of the `dds` fuzz target), by name: one of each
    /// kind of header and texels the decoder reads.
    fn seed_files() -> Vec<(&'static str, Vec<u8>)> {
        let chain = [flat(4, 2, RED), flat(2, 1, GREEN), flat(1, 1, BLUE)].concat();
        let bgra: Vec<u8> = PICTURE
            .iter()
            .flat_map(|&[r, g, b, a]| [b, g, r, a])
            .collect();
        let bc1 = bc1_block(RED_565, GREEN_565, INDICES);
        vec![
            ("bc1-dxt1.dds", dds(4, 4, 1, Pixels::FourCc(b"DXT1"), &bc1)),
            (
                "bc3-dxt5.dds",
                dds(4, 4, 1, Pixels::FourCc(b"DXT5"), &[0x5a; 16]),
            ),
            (
                "bc5-ati2.dds",
                dds(4, 4, 1, Pixels::FourCc(b"ATI2"), &[0x77; 16]),
            ),
            ("bc6h-dx10.dds", dds(4, 4, 1, Pixels::Dxgi(95), &[0x3c; 16])),
            (
                "bc7-dx10-srgb.dds",
                dds(4, 4, 1, Pixels::Dxgi(99), &[0xa5; 16]),
            ),
            ("bgra8-dx10.dds", dds(2, 2, 1, Pixels::Dxgi(87), &bgra)),
            (
                "rgba8-mips.dds",
                dds(4, 2, 3, Pixels::Masks(32, RGBA_MASKS), &chain),
            ),
        ]
    }

    /// Writes [`seed_files`] to `tests/data/dds` (the fuzz replay's seed writer copies them to
    /// `fuzz/corpus/dds`).
    #[test]
    #[ignore = "writes tests/data/dds; run by hand when the files change"]
    fn write_seed_files() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/dds");
        std::fs::create_dir_all(&dir).expect("create tests/data/dds");
        for (name, bytes) in seed_files() {
            std::fs::write(dir.join(name), bytes).expect("write a seed file");
        }
    }

    #[test]
    fn the_seed_files_are_the_committed_ones() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/dds");
        for (name, bytes) in seed_files() {
            let committed = std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(
                committed == bytes,
                "{name} differs from seed_files(): run write_seed_files"
            );
        }
    }

    #[test]
    fn fuzz_body_accepts_the_seeds_and_their_mutations() {
        for (name, seed) in &seed_files() {
            // Every seed decodes.
            decode(seed, ColorSpace::Srgb).unwrap_or_else(|e| panic!("{name}: {e}"));
            fuzz(seed);
            for at in 0..seed.len() {
                let mut flipped = seed.clone();
                flipped[at] ^= 0xff;
                fuzz(&flipped);
                fuzz(&seed[..at]);
            }
        }
    }

    /// A fresh folder under the system's temporary folder.
    fn temp_dir(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("kantele-dds-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create the folder");
        dir
    }

    /// The texture a load made from `picture.dds`: the scene's only texture, with no warning
    /// about an image.
    fn only_texture(loaded: &crate::LoadedScene) -> &Texture {
        let warnings = &loaded.info.warnings;
        assert!(
            warnings
                .iter()
                .all(|w| !w.contains(".png") && !w.contains(".dds")),
            "{warnings:?}"
        );
        assert_eq!(loaded.scene.textures.len(), 1, "{warnings:?}");
        &loaded.scene.textures[0]
    }

    #[test]
    fn gltf_uses_the_dds_image_before_its_fallback() {
        let dir = temp_dir("gltf");
        let chain = [flat(4, 2, RED), flat(2, 1, GREEN), flat(1, 1, BLUE)].concat();
        std::fs::write(
            dir.join("picture.dds"),
            dds(4, 2, 3, Pixels::Dxgi(29), &chain),
        )
        .unwrap();
        // One triangle with texture coordinates; the fallback PNG does not exist, so using it
        // would warn.
        let positions = [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let uvs = [0f32, 0.0, 1.0, 0.0, 0.0, 1.0];
        let bin: Vec<u8> = positions
            .iter()
            .chain(&uvs)
            .flat_map(|f| f.to_le_bytes())
            .collect();
        std::fs::write(dir.join("tri.bin"), bin).unwrap();
        let gltf = serde_json::json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["MSFT_texture_dds"],
            "extensionsRequired": ["MSFT_texture_dds"],
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
            "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "textures": [{"source": 0, "extensions": {"MSFT_texture_dds": {"source": 1}}}],
            "images": [{"uri": "fallback.png"}, {"uri": "picture.dds", "mimeType": "image/vnd-ms.dds"}],
            "buffers": [{"uri": "tri.bin", "byteLength": 60}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 36},
                {"buffer": 0, "byteOffset": 36, "byteLength": 24}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}
            ]
        });
        let path = dir.join("scene.gltf");
        std::fs::write(&path, serde_json::to_vec(&gltf).unwrap()).unwrap();
        let loaded = crate::load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        let texture = only_texture(&loaded);
        assert_eq!(loaded.info.texture_sizes, vec![(4, 2)]);
        assert_eq!(texture.source_color_space(), ColorSpace::Srgb);
        assert_eq!(level_texels(texture, 0), vec![RED; 8]);
        assert_eq!(level_texels(texture, 1), vec![GREEN; 2]);
        assert!(loaded
            .info
            .extensions_used
            .contains(&"MSFT_texture_dds".to_string()));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_mtl_map_may_be_a_dds_file() {
        let dir = temp_dir("obj");
        let block = bc1_block(RED_565, GREEN_565, INDICES);
        std::fs::write(
            dir.join("picture.dds"),
            dds(4, 4, 1, Pixels::FourCc(b"DXT1"), &block),
        )
        .unwrap();
        std::fs::write(
            dir.join("s.mtl"),
            "newmtl m\nKd 1 1 1\nmap_Kd picture.dds\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("s.obj"),
            "mtllib s.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n",
        )
        .unwrap();
        let loaded = crate::load_scene(&dir.join("s.obj")).unwrap_or_else(|e| panic!("{e}"));
        let texture = only_texture(&loaded);
        assert_eq!((texture.width(), texture.height()), (4, 4));
        assert_eq!(
            level_texels(texture, 0)[..4],
            [
                [255, 0, 0, 255],
                [0, 255, 0, 255],
                [170, 85, 0, 255],
                [85, 170, 0, 255]
            ]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
