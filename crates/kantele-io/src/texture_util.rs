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
/// sRGB RGB), the top-left square in `a` ([`kantele::demo::checker_texture`] for sizes that
/// cannot fail).
pub fn checker(size: u32, squares: u32, a: [u8; 3], b: [u8; 3]) -> Texture {
    kantele::demo::checker_texture(
        size.clamp(1, kantele::shade::texture::MAX_TEXTURE_SIZE),
        squares,
        a,
        b,
    )
    .expect("a clamped checker size is always valid")
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
