//! Texture decoding and procedural textures.

use kantele_rules::shade::texture::{ColorSpace, Filter, MinFilter, Sampler, Texture, Wrap};

use crate::budget::Budget;

/// Bytes of memory a decoded texture keeps per texel: `f32` RGBA plus its mip chain (4/3).
pub(crate) const TEXTURE_BYTES_PER_TEXEL: u64 = 16 * 4 / 3 + 1;

/// Why an image did not become a texture.
#[derive(Debug)]
pub(crate) enum ImageError {
    /// It would exceed the load's memory budget (always an error).
    Budget(String),
    /// It is not an image this loader can decode (a missing texture may be tolerated).
    Decode(String),
}

fn image_format(mime_type: Option<&str>) -> Option<image::ImageFormat> {
    match mime_type {
        Some("image/png") => Some(image::ImageFormat::Png),
        Some("image/jpeg") | Some("image/jpg") => Some(image::ImageFormat::Jpeg),
        Some("image/webp") => Some(image::ImageFormat::WebP),
        _ => None,
    }
}

/// A reader for the image: the format is recognised from the data (files often declare the
/// wrong MIME type), falling back to `mime_type` when the data is not recognised.
fn reader<'a>(
    bytes: &'a [u8],
    mime_type: Option<&str>,
) -> Result<image::ImageReader<std::io::Cursor<&'a [u8]>>, ImageError> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| ImageError::Decode(format!("cannot decode image: {e}")))?;
    if reader.format().is_none() {
        if let Some(format) = image_format(mime_type) {
            reader.set_format(format);
        }
    }
    Ok(reader)
}

/// The image's size from its header alone (nothing is decoded).
pub(crate) fn image_size(bytes: &[u8], mime_type: Option<&str>) -> Result<(u32, u32), ImageError> {
    if crate::ktx2_image::is_ktx2(bytes, mime_type) {
        return crate::ktx2_image::ktx2_size(bytes);
    }
    if crate::dds_image::is_dds(bytes, mime_type) {
        return crate::dds_image::dds_size(bytes);
    }
    reader(bytes, mime_type)?
        .into_dimensions()
        .map_err(|e| ImageError::Decode(format!("cannot decode image: {e}")))
}

/// Decodes an encoded PNG, JPEG, WebP, KTX2 or DDS image into a texture with its mip chain whose
/// texels are encoded in `color_space` (sRGB for colours, linear for data such as normals,
/// metallic-roughness and occlusion), after reading its size from the header and charging the
/// texture's memory to `budget`. The format is recognised from the data, `mime_type` is the
/// fallback.
pub(crate) fn decode_within(
    bytes: &[u8],
    mime_type: Option<&str>,
    color_space: ColorSpace,
    budget: &mut Budget,
) -> Result<Texture, ImageError> {
    if crate::ktx2_image::is_ktx2(bytes, mime_type) {
        return crate::ktx2_image::decode_ktx2(bytes, color_space, budget);
    }
    if crate::dds_image::is_dds(bytes, mime_type) {
        return crate::dds_image::decode_dds(bytes, color_space, budget);
    }
    let (width, height) = image_size(bytes, mime_type)?;
    let max = kantele_rules::shade::texture::MAX_TEXTURE_SIZE;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(ImageError::Decode(format!(
            "image size {width}x{height} is outside 1..={max}"
        )));
    }
    budget
        .charge(
            width as u64 * height as u64,
            TEXTURE_BYTES_PER_TEXEL,
            &format!("a {width}x{height} texture"),
        )
        .map_err(ImageError::Budget)?;
    let mut reader = reader(bytes, mime_type)?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(width);
    limits.max_image_height = Some(height);
    // The decoder's own buffers: at most 16-bit RGBA, plus the 8-bit copy.
    limits.max_alloc = Some(width as u64 * height as u64 * 12 + (1 << 20));
    reader.limits(limits);
    let decoded = reader
        .decode()
        .map_err(|e| ImageError::Decode(format!("cannot decode image: {e}")))?;
    let rgba = decoded.to_rgba8();
    drop(decoded);
    Texture::from_rgba8(rgba.width(), rgba.height(), rgba.as_raw(), color_space)
        .map_err(|e| ImageError::Decode(e.to_string()))
}

/// Decodes an encoded PNG, JPEG or WebP image into an sRGB texture with its mip chain, within
/// the default memory budget.
#[cfg(test)]
fn decode_srgb(bytes: &[u8], mime_type: Option<&str>) -> Result<Texture, String> {
    let mut budget = Budget::new(crate::DEFAULT_MAX_MEMORY);
    decode_within(bytes, mime_type, ColorSpace::Srgb, &mut budget).map_err(|e| match e {
        ImageError::Budget(m) | ImageError::Decode(m) => m,
    })
}

/// A 1 × 1 white stand-in for an image that is not decoded (scene descriptions).
pub(crate) fn placeholder() -> Texture {
    Texture::from_rgba8(1, 1, &[255; 4], ColorSpace::Srgb)
        .expect("a 1x1 texture with 4 bytes is valid")
}

/// The sampler most scenes want: REPEAT, bilinear magnification, trilinear minification.
pub fn trilinear_repeat() -> Sampler {
    Sampler {
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
        mag_filter: Filter::Linear,
        min_filter: MinFilter::LinearMipmapLinear,
    }
}

/// A `size` × `size` sRGB checkerboard of `squares` × `squares` squares in two colours (8-bit
/// sRGB RGB), the top-left square in `a`. `size` is clamped to `1..=MAX_TEXTURE_SIZE`.
pub fn checker(size: u32, squares: u32, a: [u8; 3], b: [u8; 3]) -> Texture {
    let size = size.clamp(1, kantele_rules::shade::texture::MAX_TEXTURE_SIZE);
    let cell = (size / squares.max(1)).max(1);
    let mut rgba = Vec::with_capacity(size as usize * size as usize * 4);
    for y in 0..size {
        for x in 0..size {
            let c = if ((x / cell) + (y / cell)).is_multiple_of(2) {
                a
            } else {
                b
            };
            rgba.extend_from_slice(&[c[0], c[1], c[2], 255]);
        }
    }
    Texture::from_rgba8(size, size, &rgba, ColorSpace::Srgb)
        .expect("a clamped checker size is always valid")
}

/// Reads an encoded image's size from its header.
pub(crate) type ImageSizeReader = fn(&[u8]) -> Result<(u32, u32), ImageError>;

/// Decodes an encoded image into a texture in a colour space, charging the budget.
pub(crate) type ImageDecoder = fn(&[u8], ColorSpace, &mut Budget) -> Result<Texture, ImageError>;

/// Body of the fuzz targets of an image decoder (`ktx2`, `dds`): reads the size with `size`
/// and decodes the bytes with `decode` under a 64 MiB budget. An error is a valid outcome when
/// it is one line; a panic in Kantele's own code (also one caught and turned into an error
/// starting with `malformed`), a decoded size other than the header's, or an error of several
/// lines is a defect (a panic).
pub(crate) fn fuzz_image_decoder(
    data: &[u8],
    malformed: &str,
    size: ImageSizeReader,
    decode: ImageDecoder,
) {
    let check = |error: &ImageError| {
        let (ImageError::Budget(message) | ImageError::Decode(message)) = error;
        assert!(
            !message.contains('\n'),
            "an error of several lines: {message}"
        );
        if message.starts_with(malformed) {
            let file = crate::quiet_panic::last_caught_file().unwrap_or_default();
            let file = file.replace('\\', "/");
            assert!(
                file.contains("/.cargo/") || file.contains("/rustc/") || !file.contains("kantele"),
                "Kantele's own code panicked in {file}: {message}"
            );
        }
    };
    let declared = size(data);
    if let Err(e) = &declared {
        check(e);
    }
    let mut budget = Budget::new(64 << 20);
    match decode(data, ColorSpace::Srgb, &mut budget) {
        Ok(texture) => {
            let declared = declared.unwrap_or_else(|e| panic!("decoded, but no size: {e:?}"));
            assert_eq!((texture.width(), texture.height()), declared);
        }
        Err(e) => check(&e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_has_the_asked_size_and_two_colours() {
        let t = checker(256, 8, [255, 255, 255], [0, 0, 0]);
        assert_eq!((t.width(), t.height()), (256, 256));
        assert_eq!(t.levels().len(), 9);
        let level = t.level(0).expect("level 0");
        assert_eq!(level.texel(0, 0).x, 1.0);
        assert_eq!(level.texel(32, 0).x, 0.0);
        assert_eq!(level.texel(0, 32).x, 0.0);
        assert_eq!(level.texel(32, 32).x, 1.0);
    }

    #[test]
    fn garbage_does_not_decode() {
        assert!(decode_srgb(b"not an image at all", None).is_err());
        assert!(decode_srgb(b"\x89PNG\r\n\x1a\n broken", Some("image/png")).is_err());
    }
}
