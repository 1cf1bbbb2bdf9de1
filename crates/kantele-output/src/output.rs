//! Image and array files: PNG (8-bit RGBA, 16-bit RGB, 16-bit gray), OpenEXR (float RGB/RGBA,
//! single-channel float or u32), PFM, NumPy `.npy`, written atomically — one file through
//! [`write_atomic`], or every file of a frame together through an [`OutputSet`].
//!
//! All buffers are row-major with row 0 at the top of the image (PFM stores rows bottom-up in
//! the file, as its format requires; the writer does that). Nothing here knows the CLI: the
//! Python package calls the same functions.
//!
//! Temporaries are named `.NAME.tmp-PID-N` next to the file they become. A process killed
//! before it could remove its own leaves them behind: the next write to that file removes
//! those whose process no longer runs. An [`OutputSet`] moves its files into place holding an
//! exclusive lock on each of their folders, so two processes writing the same outputs at once
//! leave one's whole set, never a mix of both.

use std::fs::File;
use std::io::{self, BufWriter, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use image::{ExtendedColorType, ImageFormat};
use thiserror::Error;

/// A file that could not be written: `path: reason`, one line.
#[derive(Debug, Error)]
#[error("{}: {message}", path.display())]
pub struct OutputError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong.
    pub message: String,
}

fn output_error(path: &Path, message: impl ToString) -> OutputError {
    OutputError {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

/// What an encoder writes into: a buffered temporary file.
pub type FileWriter = BufWriter<File>;

static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// The folder `path` is in (`.` for a bare name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// A temporary name next to `path` (same folder, so a rename moves it into place), unique per
/// process and call. Stale temporaries of `path` are removed first
/// ([`remove_stale_temporaries`]).
fn temp_path(path: &Path) -> Result<PathBuf, OutputError> {
    let dir = folder_of(path);
    let name = path
        .file_name()
        .ok_or_else(|| output_error(path, "not a file name"))?;
    remove_stale_temporaries(&dir, &name.to_string_lossy());
    let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    Ok(dir.join(format!(
        ".{}.tmp-{}-{n}",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Removes from `dir` the temporaries of the file `name` (`.NAME.tmp-PID-N`) whose process no
/// longer runs: what a killed writer left. A temporary of a running process (this one, or
/// another writing the same file now) stays; where processes cannot be looked up (outside
/// Linux), every one stays.
fn remove_stale_temporaries(dir: &Path, name: &str) {
    let prefix = format!(".{name}.tmp-");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(rest) = file_name.to_str().and_then(|f| f.strip_prefix(&prefix)) else {
            continue;
        };
        let Some((pid, counter)) = rest.split_once('-') else {
            continue;
        };
        let (Ok(pid), true) = (
            pid.parse::<u32>(),
            !counter.is_empty() && counter.bytes().all(|b| b.is_ascii_digit()),
        ) else {
            continue;
        };
        if process_ended(pid) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Whether process `pid` is known to have ended (`false` where that cannot be told).
fn process_ended(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        pid != std::process::id() && !Path::new("/proc").join(pid.to_string()).exists()
    } else {
        false
    }
}

/// Exclusive locks on the folders of `paths` (each once, in sorted order, so two sets never
/// wait on each other), held until dropped. A folder that cannot be locked is skipped: the
/// lock orders writers, it is not needed to write.
fn lock_folders<'a>(paths: impl Iterator<Item = &'a Path>) -> Vec<File> {
    let mut folders: Vec<PathBuf> = paths.map(folder_of).collect();
    folders.sort();
    folders.dedup();
    folders
        .into_iter()
        .filter_map(|dir| {
            let handle = File::open(&dir).ok()?;
            handle.lock().ok()?;
            Some(handle)
        })
        .collect()
}

/// Writes `path`'s content into a new temporary file; removes it on failure.
fn write_temp(
    path: &Path,
    write: impl FnOnce(&mut FileWriter) -> io::Result<()>,
) -> Result<PathBuf, OutputError> {
    let tmp = temp_path(path)?;
    let result = (|| -> io::Result<()> {
        let mut w = BufWriter::new(File::create(&tmp)?);
        write(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all().ok();
        Ok(())
    })();
    match result {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(output_error(path, e))
        }
    }
}

/// Flushes a writer from [`OutputSet::create`] and syncs its file, reporting errors that a
/// plain drop would lose.
pub fn close_file(writer: FileWriter) -> io::Result<()> {
    let file = writer.into_inner().map_err(|e| e.into_error())?;
    file.sync_all().ok();
    Ok(())
}

/// Writes a file through a temporary name in the same folder, renamed into place only when
/// `write` succeeded; nothing is left behind on failure.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut FileWriter) -> io::Result<()>,
) -> Result<(), OutputError> {
    let tmp = write_temp(path, write)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        output_error(path, e)
    })
}

/// Every file of one frame: each is written to a temporary file in its target folder, and
/// [`OutputSet::commit`] moves them into place together, in the order they were written (write
/// the sidecar last, so it appears only after the files it describes). Temporaries are removed
/// when a write fails and when the set is dropped without a commit.
#[derive(Debug, Default)]
pub struct OutputSet {
    /// (temporary, final path) in writing order.
    pending: Vec<(PathBuf, PathBuf)>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes `path`'s content to a temporary file (an encoder such as [`encode_png_rgba8`]
    /// or any closure). On error nothing of this file remains; the files written before stay
    /// pending.
    pub fn write(
        &mut self,
        path: &Path,
        write: impl FnOnce(&mut FileWriter) -> io::Result<()>,
    ) -> Result<(), OutputError> {
        if self.pending.iter().any(|(_, p)| p == path) {
            return Err(output_error(path, "written twice in one frame"));
        }
        let tmp = write_temp(path, write)?;
        self.pending.push((tmp, path.to_path_buf()));
        Ok(())
    }

    /// Starts `path`'s content as a temporary file that stays open for writing, for content
    /// produced piece by piece (rows streamed band by band, [`crate::row_writer`]). The
    /// temporary is pending at once: [`OutputSet::commit`] moves it into place with the
    /// others (finish writing it first), and dropping the set removes it.
    pub fn create(&mut self, path: &Path) -> Result<FileWriter, OutputError> {
        if self.pending.iter().any(|(_, p)| p == path) {
            return Err(output_error(path, "written twice in one frame"));
        }
        let tmp = temp_path(path)?;
        let file = File::create(&tmp).map_err(|e| output_error(path, e))?;
        self.pending.push((tmp, path.to_path_buf()));
        Ok(BufWriter::new(file))
    }

    /// The final paths written so far.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.pending.iter().map(|(_, p)| p.as_path())
    }

    /// Moves every file into place. If a move fails, the files not yet moved are removed and
    /// the error names the file.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let pending = std::mem::take(&mut self.pending);
        // Released when dropped, after every move.
        let _locks = lock_folders(pending.iter().map(|(_, path)| path.as_path()));
        let mut iter = pending.into_iter();
        for (tmp, path) in iter.by_ref() {
            if let Err(e) = std::fs::rename(&tmp, &path) {
                let _ = std::fs::remove_file(&tmp);
                self.pending = iter.collect(); // removed by Drop
                return Err(output_error(&path, e));
            }
        }
        Ok(())
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        for (tmp, _) in &self.pending {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

fn check_len(len: usize, width: u32, height: u32, channels: usize) -> io::Result<()> {
    let expected = (width as usize)
        .checked_mul(height as usize)
        .and_then(|n| n.checked_mul(channels));
    if expected != Some(len) || width == 0 || height == 0 {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{len} values do not make a {width}x{height} image of {channels} channel(s)"),
        ));
    }
    Ok(())
}

fn encode_image(
    out: &mut (impl Write + Seek),
    bytes: &[u8],
    width: u32,
    height: u32,
    color: ExtendedColorType,
    format: ImageFormat,
) -> io::Result<()> {
    image::write_buffer_with_format(out, bytes, width, height, color, format)
        .map_err(io::Error::other)
}

fn ne_bytes<T: Copy, const N: usize>(values: &[T], to: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    values.iter().flat_map(|&v| to(v)).collect()
}

/// Encodes 8-bit RGBA as PNG.
pub fn encode_png_rgba8(
    out: &mut (impl Write + Seek),
    width: u32,
    height: u32,
    rgba: &[u8],
) -> io::Result<()> {
    check_len(rgba.len(), width, height, 4)?;
    encode_image(
        out,
        rgba,
        width,
        height,
        ExtendedColorType::Rgba8,
        ImageFormat::Png,
    )
}

/// Encodes 16-bit RGB as PNG (PNG stores big-endian; the values are taken as numbers).
pub fn encode_png_rgb16(
    out: &mut (impl Write + Seek),
    width: u32,
    height: u32,
    rgb: &[u16],
) -> io::Result<()> {
    check_len(rgb.len(), width, height, 3)?;
    let bytes = ne_bytes(rgb, u16::to_ne_bytes);
    encode_image(
        out,
        &bytes,
        width,
        height,
        ExtendedColorType::Rgb16,
        ImageFormat::Png,
    )
}

/// Encodes one 16-bit channel as a grayscale PNG (Pillow reads it as mode `I;16`, numpy via
/// imageio as `uint16`).
pub fn encode_png_gray16(
    out: &mut (impl Write + Seek),
    width: u32,
    height: u32,
    values: &[u16],
) -> io::Result<()> {
    check_len(values.len(), width, height, 1)?;
    let bytes = ne_bytes(values, u16::to_ne_bytes);
    encode_image(
        out,
        &bytes,
        width,
        height,
        ExtendedColorType::L16,
        ImageFormat::Png,
    )
}

/// Encodes float RGB as OpenEXR (channels R, G, B).
pub fn encode_exr_rgb32f(
    out: &mut (impl Write + Seek),
    width: u32,
    height: u32,
    rgb: &[f32],
) -> io::Result<()> {
    check_len(rgb.len(), width, height, 3)?;
    let bytes = ne_bytes(rgb, f32::to_ne_bytes);
    encode_image(
        out,
        &bytes,
        width,
        height,
        ExtendedColorType::Rgb32F,
        ImageFormat::OpenExr,
    )
}

/// Encodes float RGBA as OpenEXR (channels R, G, B, A).
pub fn encode_exr_rgba32f(
    out: &mut (impl Write + Seek),
    width: u32,
    height: u32,
    rgba: &[f32],
) -> io::Result<()> {
    check_len(rgba.len(), width, height, 4)?;
    let bytes = ne_bytes(rgba, f32::to_ne_bytes);
    encode_image(
        out,
        &bytes,
        width,
        height,
        ExtendedColorType::Rgba32F,
        ImageFormat::OpenExr,
    )
}

fn encode_exr_single(
    out: &mut (impl Write + Seek),
    width: u32,
    height: u32,
    samples: exr::prelude::FlatSamples,
) -> io::Result<()> {
    use exr::prelude::*;
    let channel = AnyChannel::new("Y", samples);
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(smallvec::SmallVec::from_vec(vec![channel])),
    );
    Image::from_layer(layer)
        .write()
        .to_buffered(out)
        .map_err(io::Error::other)
}

/// Encodes one float channel (named `Y`) as OpenEXR: a quarter of the size of RGB triples.
pub fn encode_exr_gray32f(
    out: &mut (impl Write + Seek),
    width: u32,
    height: u32,
    values: &[f32],
) -> io::Result<()> {
    check_len(values.len(), width, height, 1)?;
    encode_exr_single(
        out,
        width,
        height,
        exr::prelude::FlatSamples::F32(values.to_vec()),
    )
}

/// Encodes one 32-bit unsigned integer channel (named `Y`) as OpenEXR (exact ids of any size).
pub fn encode_exr_gray_u32(
    out: &mut (impl Write + Seek),
    width: u32,
    height: u32,
    values: &[u32],
) -> io::Result<()> {
    check_len(values.len(), width, height, 1)?;
    encode_exr_single(
        out,
        width,
        height,
        exr::prelude::FlatSamples::U32(values.to_vec()),
    )
}

/// Encodes a greyscale PFM: header `Pf\n<w> <h>\n-1.0\n` (negative scale = little-endian), then
/// rows from the bottom of the image to the top. `values` is row-major with row 0 at the top.
pub fn encode_pfm(out: &mut impl Write, width: u32, height: u32, values: &[f32]) -> io::Result<()> {
    check_len(values.len(), width, height, 1)?;
    let w = width as usize;
    write!(out, "Pf\n{width} {height}\n-1.0\n")?;
    let mut row = Vec::with_capacity(w * 4);
    for line in values.chunks_exact(w).rev() {
        row.clear();
        for v in line {
            row.extend_from_slice(&v.to_le_bytes());
        }
        out.write_all(&row)?;
    }
    Ok(())
}

/// Reads a greyscale PFM (either byte order) back into row-major values, row 0 at the top.
pub fn decode_pfm(data: &[u8]) -> Result<(u32, u32, Vec<f32>), String> {
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
            return Err("PFM header is truncated".into());
        }
        fields.push(String::from_utf8_lossy(&data[start..pos]).into_owned());
    }
    pos += 1; // the single whitespace after the scale
    if fields[0] != "Pf" {
        return Err(format!("not a greyscale PFM (magic {})", fields[0]));
    }
    let number = |s: &str, what: &str| s.parse::<u32>().map_err(|e| format!("PFM {what}: {e}"));
    let width = number(&fields[1], "width")?;
    let height = number(&fields[2], "height")?;
    let scale: f32 = fields[3].parse().map_err(|e| format!("PFM scale: {e}"))?;
    let (w, h) = (width as usize, height as usize);
    let body = w
        .checked_mul(h)
        .and_then(|n| n.checked_mul(4))
        .and_then(|n| data.get(pos..pos.checked_add(n)?))
        .ok_or("PFM data is truncated")?;
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

/// The element type and values of a `.npy` array.
#[derive(Clone, Copy, Debug)]
pub enum NpyData<'a> {
    /// `float32` (`<f4`).
    F32(&'a [f32]),
    /// `uint16` (`<u2`).
    U16(&'a [u16]),
    /// `uint32` (`<u4`).
    U32(&'a [u32]),
}

impl NpyData<'_> {
    fn len(&self) -> usize {
        match self {
            NpyData::F32(v) => v.len(),
            NpyData::U16(v) => v.len(),
            NpyData::U32(v) => v.len(),
        }
    }

    fn descr(&self) -> &'static str {
        match self {
            NpyData::F32(_) => "<f4",
            NpyData::U16(_) => "<u2",
            NpyData::U32(_) => "<u4",
        }
    }
}

/// Writes the header of a C-order NumPy array (format 1.0) of `shape` and element type `descr`
/// (`<f4`, `<u2`, `<u4`); the values follow it, little-endian.
pub(crate) fn write_npy_header(
    out: &mut impl Write,
    shape: &[usize],
    descr: &str,
) -> io::Result<()> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    // A 1-tuple needs its comma.
    let comma = if dims.len() == 1 { "," } else { "" };
    let mut header = format!(
        "{{'descr': '{descr}', 'fortran_order': False, 'shape': ({}{comma}), }}",
        dims.join(", ")
    );
    // Magic (6) + version (2) + length (2) + header + '\n' is a multiple of 64.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat(unpadded.next_multiple_of(64) - unpadded));
    header.push('\n');
    out.write_all(b"\x93NUMPY\x01\x00")?;
    out.write_all(&(header.len() as u16).to_le_bytes())?;
    out.write_all(header.as_bytes())
}

/// Encodes a C-order NumPy array (format 1.0) of shape `(H, W)` or `(H, W, C)`, little-endian.
pub fn encode_npy(out: &mut impl Write, shape: &[usize], data: NpyData<'_>) -> io::Result<()> {
    let count = shape.iter().try_fold(1usize, |n, &d| n.checked_mul(d));
    if !(shape.len() == 2 || shape.len() == 3) || count != Some(data.len()) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} values do not make an array of shape {shape:?} (use (H, W) or (H, W, C))",
                data.len()
            ),
        ));
    }
    write_npy_header(out, shape, data.descr())?;
    match data {
        NpyData::F32(v) => out.write_all(&ne_bytes(v, f32::to_le_bytes)),
        NpyData::U16(v) => out.write_all(&ne_bytes(v, u16::to_le_bytes)),
        NpyData::U32(v) => out.write_all(&ne_bytes(v, u32::to_le_bytes)),
    }
}

/// 8-bit RGBA PNG, written atomically.
pub fn write_png_rgba8(
    path: &Path,
    width: u32,
    height: u32,
    rgba: &[u8],
) -> Result<(), OutputError> {
    write_atomic(path, |w| encode_png_rgba8(w, width, height, rgba))
}

/// 16-bit RGB PNG, written atomically.
pub fn write_png_rgb16(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u16],
) -> Result<(), OutputError> {
    write_atomic(path, |w| encode_png_rgb16(w, width, height, rgb))
}

/// 16-bit grayscale PNG, written atomically.
pub fn write_png_gray16(
    path: &Path,
    width: u32,
    height: u32,
    values: &[u16],
) -> Result<(), OutputError> {
    write_atomic(path, |w| encode_png_gray16(w, width, height, values))
}

/// Float RGB OpenEXR, written atomically.
pub fn write_exr_rgb32f(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[f32],
) -> Result<(), OutputError> {
    write_atomic(path, |w| encode_exr_rgb32f(w, width, height, rgb))
}

/// Float RGBA OpenEXR, written atomically.
pub fn write_exr_rgba32f(
    path: &Path,
    width: u32,
    height: u32,
    rgba: &[f32],
) -> Result<(), OutputError> {
    write_atomic(path, |w| encode_exr_rgba32f(w, width, height, rgba))
}

/// Single-channel float OpenEXR, written atomically.
pub fn write_exr_gray32f(
    path: &Path,
    width: u32,
    height: u32,
    values: &[f32],
) -> Result<(), OutputError> {
    write_atomic(path, |w| encode_exr_gray32f(w, width, height, values))
}

/// Single-channel u32 OpenEXR, written atomically.
pub fn write_exr_gray_u32(
    path: &Path,
    width: u32,
    height: u32,
    values: &[u32],
) -> Result<(), OutputError> {
    write_atomic(path, |w| encode_exr_gray_u32(w, width, height, values))
}

/// Greyscale PFM, written atomically.
pub fn write_pfm(path: &Path, width: u32, height: u32, values: &[f32]) -> Result<(), OutputError> {
    write_atomic(path, |w| encode_pfm(w, width, height, values))
}

/// `.npy` array, written atomically.
pub fn write_npy(path: &Path, shape: &[usize], data: NpyData<'_>) -> Result<(), OutputError> {
    write_atomic(path, |w| encode_npy(w, shape, data))
}

#[cfg(test)]
mod tests {
    use super::*;

    struct TempDir(PathBuf);

    impl TempDir {
        fn new(name: &str) -> Self {
            let dir = std::env::temp_dir().join(format!(
                "kantele-scene-output-{name}-{}",
                std::process::id()
            ));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            Self(dir)
        }
        fn files(&self) -> Vec<String> {
            let mut v: Vec<String> = std::fs::read_dir(&self.0)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    #[test]
    fn pfm_round_trip() {
        let values = vec![0.0, 1.5, f32::INFINITY, -2.0, 0.25, 1e-7];
        let mut bytes = Vec::new();
        encode_pfm(&mut bytes, 3, 2, &values).unwrap();
        assert!(bytes.starts_with(b"Pf\n3 2\n-1.0\n"));
        // Bottom row first in the file.
        let body = &bytes[b"Pf\n3 2\n-1.0\n".len()..];
        assert_eq!(body.len(), 24);
        assert_eq!(f32::from_le_bytes(body[0..4].try_into().unwrap()), -2.0);
        assert_eq!(decode_pfm(&bytes).unwrap(), (3, 2, values));
        assert!(decode_pfm(b"Pf\n3 2\n-1.0\n\0\0").is_err());
        assert!(encode_pfm(&mut Vec::new(), 3, 3, &[0.0; 6]).is_err());
    }

    #[test]
    fn npy_header_and_data() {
        let mut bytes = Vec::new();
        let v: Vec<u32> = (0..12).map(|i| i * 70_000).collect();
        encode_npy(&mut bytes, &[2, 3, 2], NpyData::U32(&v)).unwrap();
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + hlen) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + hlen]).unwrap();
        assert!(
            header.starts_with("{'descr': '<u4', 'fortran_order': False, 'shape': (2, 3, 2), }")
        );
        assert!(header.ends_with('\n'));
        let body = &bytes[10 + hlen..];
        assert_eq!(body.len(), 48);
        assert_eq!(
            u32::from_le_bytes(body[44..48].try_into().unwrap()),
            11 * 70_000
        );
        let mut f = Vec::new();
        encode_npy(&mut f, &[1, 2], NpyData::F32(&[1.5, f32::INFINITY])).unwrap();
        assert!(String::from_utf8_lossy(&f[10..]).contains("'<f4'"));
        let mut g = Vec::new();
        encode_npy(&mut g, &[2, 2], NpyData::U16(&[1, 2, 3, 65535])).unwrap();
        assert_eq!(&g[g.len() - 2..], &[255, 255]);
        assert!(encode_npy(&mut Vec::new(), &[2, 2], NpyData::U16(&[1, 2, 3])).is_err());
        assert!(encode_npy(&mut Vec::new(), &[4], NpyData::U16(&[1, 2, 3, 4])).is_err());
    }

    #[test]
    fn single_channel_files_read_back() {
        let dir = TempDir::new("gray");
        let gray = dir.0.join("ids.png");
        write_png_gray16(&gray, 3, 2, &[0, 1, 3, 300, 65535, 7]).unwrap();
        let img = image::open(&gray).unwrap();
        assert_eq!(img.color(), image::ColorType::L16);
        assert_eq!(img.to_luma16().into_raw(), vec![0, 1, 3, 300, 65535, 7]);

        let exr_path = dir.0.join("depth.exr");
        let depth = [1.0f32, 0.5, f32::INFINITY, 1e-30, 7.25, 3.0];
        write_exr_gray32f(&exr_path, 3, 2, &depth).unwrap();
        let read = exr::prelude::read_first_flat_layer_from_file(&exr_path).unwrap();
        let channels = &read.layer_data.channel_data.list;
        assert_eq!(channels.len(), 1, "one channel, not RGB");
        assert_eq!(
            channels[0].sample_data.values_as_f32().collect::<Vec<_>>(),
            depth
        );

        let ids_path = dir.0.join("ids.exr");
        let ids = [0u32, 1, 70_000, 16_777_217, u32::MAX, 5];
        write_exr_gray_u32(&ids_path, 3, 2, &ids).unwrap();
        let read = exr::prelude::read_first_flat_layer_from_file(&ids_path).unwrap();
        match &read.layer_data.channel_data.list[0].sample_data {
            exr::prelude::FlatSamples::U32(v) => assert_eq!(v, &ids),
            other => panic!("not u32: {other:?}"),
        }
        let rgba = dir.0.join("c.exr");
        write_exr_rgba32f(&rgba, 1, 1, &[0.25, 0.5, 2.0, 1.0]).unwrap();
        assert_eq!(
            image::open(&rgba).unwrap().to_rgba32f().into_raw(),
            vec![0.25, 0.5, 2.0, 1.0]
        );
        assert!(write_png_gray16(&dir.0.join("bad.png"), 3, 3, &[0; 6]).is_err());
        assert_eq!(
            dir.files(),
            vec!["c.exr", "depth.exr", "ids.exr", "ids.png"]
        );
    }

    #[test]
    fn atomic_write_leaves_nothing_on_failure() {
        let dir = TempDir::new("atomic");
        let path = dir.0.join("x.bin");
        let r = write_atomic(&path, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("boom"))
        });
        let e = r.unwrap_err().to_string();
        assert!(e.contains("x.bin") && e.contains("boom"), "{e}");
        assert!(dir.files().is_empty());
        write_atomic(&path, |w| w.write_all(b"ok")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"ok");
    }

    #[test]
    fn output_set_moves_files_together() {
        let dir = TempDir::new("set");
        let (a, b, side) = (
            dir.0.join("a.png"),
            dir.0.join("a.pfm"),
            dir.0.join("a.png.json"),
        );
        // A failing file: nothing appears, temporaries are gone once the set is dropped.
        {
            let mut set = OutputSet::new();
            set.write(&a, |w| encode_png_rgba8(w, 1, 1, &[1, 2, 3, 4]))
                .unwrap();
            assert!(set.write(&b, |w| encode_pfm(w, 2, 2, &[0.0])).is_err());
            assert_eq!(
                dir.files().len(),
                1,
                "only a's temporary: {:?}",
                dir.files()
            );
            assert!(!a.exists());
        }
        assert!(dir.files().is_empty(), "{:?}", dir.files());
        // All written: nothing in place until the commit.
        let mut set = OutputSet::new();
        set.write(&a, |w| encode_png_rgba8(w, 1, 1, &[1, 2, 3, 4]))
            .unwrap();
        set.write(&b, |w| encode_pfm(w, 1, 1, &[2.5])).unwrap();
        set.write(&side, |w| w.write_all(b"{}")).unwrap();
        assert!(set.write(&a, |w| w.write_all(b"again")).is_err());
        assert_eq!(set.paths().count(), 3);
        assert!(!a.exists() && !b.exists() && !side.exists());
        set.commit().unwrap();
        assert_eq!(dir.files(), vec!["a.pfm", "a.png", "a.png.json"]);
        assert_eq!(
            decode_pfm(&std::fs::read(&b).unwrap()).unwrap(),
            (1, 1, vec![2.5])
        );
        // A commit that cannot move a file (its target is a folder) removes what is left.
        let blocked = dir.0.join("blocked");
        std::fs::create_dir(&blocked).unwrap();
        std::fs::write(blocked.join("keep"), b"x").unwrap();
        let mut set = OutputSet::new();
        set.write(&blocked, |w| w.write_all(b"1")).unwrap();
        set.write(&dir.0.join("later.json"), |w| w.write_all(b"2"))
            .unwrap();
        assert!(set.commit().unwrap_err().to_string().contains("blocked"));
        assert_eq!(dir.files(), vec!["a.pfm", "a.png", "a.png.json", "blocked"]);
    }

    /// A later write to a file removes the temporaries a killed writer of that file left (its
    /// process is gone), and nothing else: not those of a running process, not other names.
    #[cfg(target_os = "linux")]
    #[test]
    fn stale_temporaries_of_ended_processes_are_removed() {
        let dir = TempDir::new("stale");
        let out = dir.0.join("a.png");
        // No process has this id (above Linux's largest pid_max).
        let stale = ".a.png.tmp-999999999-0";
        let running = format!(".a.png.tmp-{}-77", std::process::id());
        let keep = [
            ".a.png.tmp-x",
            ".b.png.tmp-999999999-0",
            "a.png.tmp-999999999-0",
        ];
        for name in [stale, running.as_str()].into_iter().chain(keep) {
            std::fs::write(dir.0.join(name), b"old").unwrap();
        }
        write_atomic(&out, |w| w.write_all(b"new")).unwrap();
        let files = dir.files();
        assert!(!files.contains(&stale.to_string()), "{files:?}");
        assert!(files.contains(&running), "{files:?}");
        for name in keep {
            assert!(files.contains(&name.to_string()), "{name}: {files:?}");
        }
        assert_eq!(std::fs::read(&out).unwrap(), b"new");
    }

    /// Two writers committing sets of the same two files, over and over: whenever the folder
    /// is quiet (its lock held by the reader), both files come from the same set.
    #[cfg(unix)]
    #[test]
    fn concurrent_sets_never_mix() {
        let dir = TempDir::new("concurrent");
        let (a, b) = (dir.0.join("a.txt"), dir.0.join("b.txt"));
        let stop = std::sync::atomic::AtomicBool::new(false);
        let mut mixed = 0;
        std::thread::scope(|scope| {
            for writer in ["first", "second"] {
                let (a, b, stop) = (&a, &b, &stop);
                scope.spawn(move || {
                    let mut round = 0;
                    while !stop.load(Ordering::Relaxed) {
                        let text = format!("{writer} {round}");
                        let mut set = OutputSet::new();
                        set.write(a, |w| w.write_all(text.as_bytes())).unwrap();
                        set.write(b, |w| w.write_all(text.as_bytes())).unwrap();
                        set.commit().unwrap();
                        round += 1;
                    }
                });
            }
            let mut checked = 0;
            while checked < 300 {
                let folder = File::open(&dir.0).unwrap();
                folder.lock().unwrap();
                if let (Ok(x), Ok(y)) = (std::fs::read(&a), std::fs::read(&b)) {
                    mixed += usize::from(x != y);
                    checked += 1;
                }
                drop(folder);
                std::thread::yield_now();
            }
            stop.store(true, Ordering::Relaxed);
        });
        assert_eq!(mixed, 0, "sets mixed");
    }
}
