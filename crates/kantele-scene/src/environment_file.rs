//! Environment images: equirectangular Radiance HDR (`.hdr`) and OpenEXR (`.exr`) files decoded
//! into linear RGB and prepared for image-based light once per file and process.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use glam::Vec3;
use kantele_rules::shade::environment::{Environment, MAX_ENVIRONMENT_SIZE};

use crate::budget::Budget;
use crate::read_policy::read_regular_file;

/// Bytes a decoded environment texel takes while it is prepared (`f32` RGB twice: the
/// decoder's image and the copy handed to the preparation).
const BYTES_PER_TEXEL: u64 = 24;

/// The prepared environment of `path`, read and prepared on first use and kept for the rest of
/// the process (a run renders many scenes under one environment). Errors are one line.
pub(crate) fn load_environment(
    path: &Path,
    budget: &mut Budget,
) -> Result<Arc<Environment>, String> {
    static CACHE: OnceLock<Mutex<HashMap<PathBuf, Arc<Environment>>>> = OnceLock::new();
    let key = path.canonicalize().map_err(|e| e.to_string())?;
    let cache = CACHE.get_or_init(Default::default);
    if let Some(env) = cache.lock().map_err(|e| e.to_string())?.get(&key) {
        return Ok(env.clone());
    }
    let env = Arc::new(decode(&key, budget)?);
    cache
        .lock()
        .map_err(|e| e.to_string())?
        .insert(key, env.clone());
    Ok(env)
}

fn decode(path: &Path, budget: &mut Budget) -> Result<Environment, String> {
    let bytes = read_regular_file(path, budget)?;
    let reader = image::ImageReader::new(std::io::Cursor::new(&bytes[..]))
        .with_guessed_format()
        .map_err(|e| format!("cannot read the environment image: {e}"))?;
    let format = reader.format();
    if !matches!(
        format,
        Some(image::ImageFormat::Hdr) | Some(image::ImageFormat::OpenExr)
    ) {
        return Err(
            "an environment must be an equirectangular Radiance HDR (.hdr) or OpenEXR (.exr) image"
                .into(),
        );
    }
    let (width, height) = reader
        .into_dimensions()
        .map_err(|e| format!("cannot read the environment image: {e}"))?;
    if width < 2 || height < 1 || width > MAX_ENVIRONMENT_SIZE || height > MAX_ENVIRONMENT_SIZE {
        return Err(format!(
            "the environment image is {width}x{height}; it must be 2..={MAX_ENVIRONMENT_SIZE} wide and 1..={MAX_ENVIRONMENT_SIZE} high"
        ));
    }
    budget.charge(
        width as u64 * height as u64,
        BYTES_PER_TEXEL,
        &format!("a {width}x{height} environment image"),
    )?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(&bytes[..]))
        .with_guessed_format()
        .map_err(|e| format!("cannot read the environment image: {e}"))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(width);
    limits.max_image_height = Some(height);
    limits.max_alloc = Some(width as u64 * height as u64 * 32 + (1 << 20));
    reader.limits(limits);
    let image = reader
        .decode()
        .map_err(|e| format!("cannot decode the environment image: {e}"))?
        .into_rgb32f();
    let texels: Vec<Vec3> = image
        .pixels()
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    drop(bytes);
    Environment::from_equirect(image.width(), image.height(), &texels).map_err(|e| e.to_string())
}
