//! Output files: name templates, atomic writes (temp file + rename), PNG / EXR / PFM writers.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use image::{ExtendedColorType, ImageFormat};

/// Values that fill an output name template.
#[derive(Clone, Copy, Debug)]
pub struct TemplateVars<'a> {
    /// The scene's file stem or built-in name.
    pub stem: &'a str,
    /// The image's number among every image of the command.
    pub index: usize,
    /// The orbit view's number (0 without --orbit).
    pub frame: usize,
}

/// Digits a zero-padded number gets (at least 4, more when needed).
pub const MIN_DIGITS: usize = 4;

/// Whether the template has any placeholder.
pub fn has_placeholder(template: &str) -> bool {
    ["{stem}", "{index}", "{frame}"]
        .iter()
        .any(|p| template.contains(p))
}

/// Expands `{stem}`, `{index}` and `{frame}`; numbers are zero-padded to `digits`. Any other
/// `{...}` is an error.
pub fn expand_template(template: &str, vars: &TemplateVars, digits: usize) -> Result<String> {
    let mut out = String::with_capacity(template.len() + 16);
    let mut rest = template;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let after = &rest[open..];
        let close = after
            .find('}')
            .ok_or_else(|| anyhow!("{template}: unclosed '{{' in output template"))?;
        match &after[..=close] {
            "{stem}" => out.push_str(vars.stem),
            "{index}" => out.push_str(&format!("{:0digits$}", vars.index)),
            "{frame}" => out.push_str(&format!("{:0digits$}", vars.frame)),
            other => bail!(
                "{template}: unknown placeholder {other} in output template (use {{stem}}, {{index}} or {{frame}})"
            ),
        }
        rest = &after[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Digits for numbers below `count`.
pub fn digits_for(count: usize) -> usize {
    count
        .saturating_sub(1)
        .max(1)
        .to_string()
        .len()
        .max(MIN_DIGITS)
}

/// Lower-case extension of a path.
pub fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// Writes a file through a temporary name in the same directory, renamed into place only when
/// `write` succeeded; nothing is left behind on failure.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<()>,
) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| anyhow!("{}: not a file name", path.display()))?;
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| -> Result<()> {
        let file = File::create(&tmp).map_err(|e| anyhow!("{}: {e}", path.display()))?;
        let mut w = BufWriter::new(file);
        write(&mut w)?;
        let file = w
            .into_inner()
            .map_err(|e| anyhow!("{}: {}", path.display(), e.error()))?;
        file.sync_all().ok();
        drop(file);
        std::fs::rename(&tmp, path).map_err(|e| anyhow!("{}: {e}", path.display()))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn encode(
    path: &Path,
    bytes: &[u8],
    width: u32,
    height: u32,
    color: ExtendedColorType,
    format: ImageFormat,
) -> Result<()> {
    write_atomic(path, |w| {
        image::write_buffer_with_format(w, bytes, width, height, color, format)
            .map_err(|e| anyhow!("{}: {e}", path.display()))
    })
}

/// 8-bit RGBA PNG.
pub fn write_png_rgba8(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    encode(
        path,
        rgba,
        width,
        height,
        ExtendedColorType::Rgba8,
        ImageFormat::Png,
    )
}

/// 16-bit RGB PNG (values stored big-endian as PNG requires; the encoder takes native u16).
pub fn write_png_rgb16(path: &Path, width: u32, height: u32, rgb: &[u16]) -> Result<()> {
    let bytes: Vec<u8> = rgb.iter().flat_map(|v| v.to_ne_bytes()).collect();
    encode(
        path,
        &bytes,
        width,
        height,
        ExtendedColorType::Rgb16,
        ImageFormat::Png,
    )
}

/// Float RGB OpenEXR.
pub fn write_exr_rgb32f(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<()> {
    let bytes: Vec<u8> = rgb.iter().flat_map(|v| v.to_ne_bytes()).collect();
    encode(
        path,
        &bytes,
        width,
        height,
        ExtendedColorType::Rgb32F,
        ImageFormat::OpenExr,
    )
}

/// Float RGBA OpenEXR.
pub fn write_exr_rgba32f(path: &Path, width: u32, height: u32, rgba: &[f32]) -> Result<()> {
    let bytes: Vec<u8> = rgba.iter().flat_map(|v| v.to_ne_bytes()).collect();
    encode(
        path,
        &bytes,
        width,
        height,
        ExtendedColorType::Rgba32F,
        ImageFormat::OpenExr,
    )
}

/// Encodes a greyscale PFM: header `Pf\n<w> <h>\n-1.0\n` (negative scale = little-endian), then
/// rows from the bottom of the image to the top. `values` is row-major with row 0 at the top.
pub fn encode_pfm(
    out: &mut impl Write,
    width: u32,
    height: u32,
    values: &[f32],
) -> std::io::Result<()> {
    let (w, h) = (width as usize, height as usize);
    assert_eq!(values.len(), w * h, "PFM data does not match its size");
    write!(out, "Pf\n{width} {height}\n-1.0\n")?;
    let mut row = Vec::with_capacity(w * 4);
    for y in (0..h).rev() {
        row.clear();
        for v in &values[y * w..(y + 1) * w] {
            row.extend_from_slice(&v.to_le_bytes());
        }
        out.write_all(&row)?;
    }
    Ok(())
}

/// Writes a greyscale PFM file atomically.
pub fn write_pfm(path: &Path, width: u32, height: u32, values: &[f32]) -> Result<()> {
    write_atomic(path, |w| {
        encode_pfm(w, width, height, values).map_err(|e| anyhow!("{}: {e}", path.display()))
    })
}

/// Reads a greyscale PFM (either byte order) back into row-major values, row 0 at the top.
#[cfg(test)]
pub fn decode_pfm(mut input: impl std::io::Read) -> Result<(u32, u32, Vec<f32>)> {
    use anyhow::Context;
    let mut data = Vec::new();
    input.read_to_end(&mut data)?;
    let mut fields = Vec::new();
    let mut pos = 0;
    while fields.len() < 4 {
        while pos < data.len() && data[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < data.len() && !data[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos {
            bail!("PFM header is truncated");
        }
        fields.push(std::str::from_utf8(&data[start..pos])?.to_string());
    }
    pos += 1; // the single whitespace after the scale
    if fields[0] != "Pf" {
        bail!("not a greyscale PFM (magic {})", fields[0]);
    }
    let width: u32 = fields[1].parse().context("PFM width")?;
    let height: u32 = fields[2].parse().context("PFM height")?;
    let scale: f32 = fields[3].parse().context("PFM scale")?;
    let (w, h) = (width as usize, height as usize);
    let body = data
        .get(pos..pos + w * h * 4)
        .ok_or_else(|| anyhow!("PFM data is truncated"))?;
    let mut values = vec![0.0; w * h];
    for (i, chunk) in body.chunks_exact(4).enumerate() {
        let b = [chunk[0], chunk[1], chunk[2], chunk[3]];
        let v = if scale < 0.0 {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        };
        let (file_row, x) = (i / w, i % w);
        values[(h - 1 - file_row) * w + x] = v;
    }
    Ok((width, height, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vars(stem: &str, index: usize, frame: usize) -> TemplateVars<'_> {
        TemplateVars { stem, index, frame }
    }

    #[test]
    fn template_expansion() {
        let v = vars("bunny", 7, 12);
        assert_eq!(
            expand_template("out/{stem}.png", &v, 4).unwrap(),
            "out/bunny.png"
        );
        assert_eq!(
            expand_template("{stem}-{index}-{frame}.png", &v, 4).unwrap(),
            "bunny-0007-0012.png"
        );
        assert_eq!(expand_template("plain.png", &v, 4).unwrap(), "plain.png");
        assert_eq!(
            expand_template("{frame}", &vars("x", 0, 123456), 4).unwrap(),
            "123456"
        );
        assert!(expand_template("{nope}.png", &v, 4).is_err());
        assert!(expand_template("{stem.png", &v, 4).is_err());
        assert!(has_placeholder("a/{index}.png"));
        assert!(!has_placeholder("a/index.png"));
    }

    #[test]
    fn digits() {
        assert_eq!(digits_for(0), 4);
        assert_eq!(digits_for(1), 4);
        assert_eq!(digits_for(10000), 4);
        assert_eq!(digits_for(10001), 5);
    }

    #[test]
    fn pfm_round_trip() {
        let (w, h) = (3u32, 2u32);
        let values = vec![0.0, 1.5, f32::INFINITY, -2.0, 0.25, 1e-7];
        let mut bytes = Vec::new();
        encode_pfm(&mut bytes, w, h, &values).unwrap();
        assert!(bytes.starts_with(b"Pf\n3 2\n-1.0\n"));
        // Bottom row first in the file.
        let body = &bytes[b"Pf\n3 2\n-1.0\n".len()..];
        assert_eq!(body.len(), 24);
        assert_eq!(f32::from_le_bytes(body[0..4].try_into().unwrap()), -2.0);
        let (rw, rh, back) = decode_pfm(&bytes[..]).unwrap();
        assert_eq!((rw, rh), (w, h));
        assert_eq!(back, values);
    }

    #[test]
    fn atomic_write_leaves_nothing_on_failure() {
        let dir = std::env::temp_dir().join(format!("kantele-out-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("x.bin");
        let r = write_atomic(&path, |w| {
            w.write_all(b"partial")?;
            bail!("boom")
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        write_atomic(&path, |w| Ok(w.write_all(b"ok")?)).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"ok");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
