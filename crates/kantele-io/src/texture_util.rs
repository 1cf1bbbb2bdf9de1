//! Texture decoding and procedural textures.

use kantele::shade::texture::{ColorSpace, Filter, MinFilter, Sampler, Texture, Wrap};

/// Decodes an encoded PNG or JPEG image into an sRGB texture with its mip chain. `mime_type`
/// picks the decoder when given; otherwise the format is guessed from the data.
pub fn decode_srgb(bytes: &[u8], mime_type: Option<&str>) -> Result<Texture, String> {
    let format = match mime_type {
        Some("image/png") => Some(image::ImageFormat::Png),
        Some("image/jpeg") | Some("image/jpg") => Some(image::ImageFormat::Jpeg),
        _ => None,
    };
    let decoded = match format {
        Some(format) => image::load_from_memory_with_format(bytes, format),
        None => image::load_from_memory(bytes),
    }
    .map_err(|e| format!("cannot decode image: {e}"))?;
    let rgba = decoded.to_rgba8();
    Texture::from_rgba8(rgba.width(), rgba.height(), rgba.as_raw(), ColorSpace::Srgb)
        .map_err(|e| e.to_string())
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
/// sRGB RGB), the top-left square in `a`.
pub fn checker(size: u32, squares: u32, a: [u8; 3], b: [u8; 3]) -> Texture {
    let size = size.max(1);
    let cell = (size / squares.max(1)).max(1);
    let mut rgba = Vec::with_capacity(size as usize * size as usize * 4);
    for y in 0..size {
        for x in 0..size {
            let c = if ((x / cell) + (y / cell)) % 2 == 0 {
                a
            } else {
                b
            };
            rgba.extend([c[0], c[1], c[2], 255]);
        }
    }
    Texture::from_rgba8(size, size, &rgba, ColorSpace::Srgb)
        .expect("a generated checker has a valid size and matching data")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_has_the_asked_size_and_two_colours() {
        let t = checker(256, 8, [255, 255, 255], [0, 0, 0]);
        assert_eq!((t.width(), t.height()), (256, 256));
        assert_eq!(t.levels().len(), 9);
        let level = &t.levels()[0];
        assert_eq!(level.texels[0].x, 1.0);
        assert_eq!(level.texels[32].x, 0.0);
        assert_eq!(level.texels[32 * 256].x, 0.0);
        assert_eq!(level.texels[32 * 256 + 32].x, 1.0);
    }

    #[test]
    fn garbage_does_not_decode() {
        assert!(decode_srgb(b"not an image at all", None).is_err());
        assert!(decode_srgb(b"\x89PNG\r\n\x1a\n broken", Some("image/png")).is_err());
    }
}
