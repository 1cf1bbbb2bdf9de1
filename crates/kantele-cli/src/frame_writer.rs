//! The files of one image written a band of rows at a time: each output (colour, depth,
//! normals, one per id kind) is opened once in the frame's [`OutputSet`], fed every band of
//! its pass top to bottom, and finished before the sidecar is written. PNG, PFM and `.npy` are
//! streamed ([`kantele_output::row_writer`]); OpenEXR is written whole and so only for pictures
//! rendered in one band.

use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use kantele::backend::FrameImage;
use kantele::scene::Scene;
use kantele_output::output::{
    close_file, encode_exr_gray32f, encode_exr_gray_u32, encode_exr_rgb32f, encode_exr_rgba32f,
    FileWriter, OutputSet,
};
use kantele_output::pose::CameraPose;
use kantele_output::row_writer::{RowWriter, Rows, SampleKind};

use crate::cli::{DepthKind, DepthUnit, IdKind, NormalSpace};
use crate::frame_files::{depth_png, depth_values, id_values, normal_values};
use crate::output::extension;
use crate::signals::InterruptFlag;

/// What an output file holds.
#[derive(Clone, Copy, Debug)]
pub enum Content {
    /// The shaded picture (from the colour pass).
    Color,
    /// Depth of `kind` in `unit` (from the colour pass).
    Depth(DepthKind, DepthUnit),
    /// Unit normals in `space` (from the normals pass).
    Normals(NormalSpace),
    /// Ids of one kind (from the ids pass).
    Ids(IdKind),
}

/// Where a file's bytes go.
enum Sink {
    /// Rows streamed into a temporary file of the set.
    File(RowWriter<FileWriter>),
    /// Rows encoded in memory, for standard output (written whole at the end, so a failed
    /// frame writes nothing).
    Memory(RowWriter<Cursor<Vec<u8>>>),
    /// OpenEXR: encoded from the whole frame, which arrives as the only band.
    Exr,
}

/// One output file of an image, fed band by band.
pub struct OutputFile {
    path: Option<PathBuf>,
    content: Content,
    sink: Sink,
}

/// What a band needs besides its frame: the camera and scene, and the band's first row.
pub struct BandContext<'a> {
    /// The image's camera (depth and camera-space normals).
    pub pose: &'a CameraPose,
    /// The scene (ids of meshes and materials).
    pub scene: &'a Scene,
    /// The picture row the band starts at.
    pub first_row: u32,
    /// Checked between small groups of rows, so an interrupt stops a big band's encoding.
    pub interrupt: &'a InterruptFlag,
}

/// Rows converted and encoded between two interrupt checks.
const ROWS_PER_CHECK: usize = 16;

/// The row format of `content` in a file of type `ext`: (channels, sample kind) for `.npy`;
/// PNG and PFM are fixed by the content.
fn npy_layout(content: Content) -> (usize, SampleKind) {
    match content {
        Content::Color => (4, SampleKind::F32),
        Content::Depth(..) => (1, SampleKind::F32),
        Content::Normals(_) => (3, SampleKind::F32),
        Content::Ids(_) => (1, SampleKind::U32),
    }
}

fn row_writer<W: Write + std::io::Seek + 'static>(
    out: W,
    ext: &str,
    content: Content,
    width: u32,
    height: u32,
) -> std::io::Result<RowWriter<W>> {
    match (ext, content) {
        ("npy", c) => {
            let (channels, kind) = npy_layout(c);
            RowWriter::npy(out, width, height, channels, kind)
        }
        ("pfm", _) => RowWriter::pfm(out, width, height),
        ("png", Content::Color | Content::Normals(_)) => RowWriter::png_rgba8(out, width, height),
        _ => RowWriter::png_gray16(out, width, height),
    }
}

impl OutputFile {
    /// Opens `path` (`None`: standard output, PNG) for `content` of a `width × height`
    /// picture rendered in `bands` bands.
    pub fn open(
        set: &mut OutputSet,
        path: Option<&Path>,
        content: Content,
        (width, height): (u32, u32),
        bands: usize,
    ) -> Result<Self> {
        let ext = path.map_or_else(|| "png".to_string(), extension);
        let sink = match path {
            _ if ext == "exr" => {
                if bands > 1 {
                    bail!(
                        "{}: OpenEXR is written whole, and this {width}x{height} picture is rendered in {bands} bands within the frame memory budget; use .png, .pfm or .npy, or raise --frame-memory",
                        path.map_or("-".into(), |p| p.display().to_string())
                    );
                }
                Sink::Exr
            }
            None => Sink::Memory(row_writer(
                Cursor::new(Vec::new()),
                &ext,
                content,
                width,
                height,
            )?),
            Some(p) => {
                let file = set.create(p)?;
                let writer = row_writer(file, &ext, content, width, height)
                    .map_err(|e| anyhow!("{}: {e}", p.display()))?;
                Sink::File(writer)
            }
        };
        Ok(Self {
            path: path.map(Path::to_path_buf),
            content,
            sink,
        })
    }

    fn name(&self) -> String {
        self.path
            .as_ref()
            .map_or("standard output".into(), |p| p.display().to_string())
    }

    /// Whether this file is fed from the normals pass.
    pub fn needs_normals_pass(&self) -> bool {
        matches!(self.content, Content::Normals(_))
    }

    /// Whether this file is fed from the ids pass.
    pub fn needs_ids_pass(&self) -> bool {
        matches!(self.content, Content::Ids(_))
    }

    /// Appends the rows of `band` (a frame of the pass this file is fed from), converted and
    /// encoded a few rows at a time with an interrupt check in between.
    pub fn write_band(
        &mut self,
        set: &mut OutputSet,
        band: &FrameImage,
        ctx: &BandContext<'_>,
    ) -> Result<()> {
        if let Sink::Exr = self.sink {
            let path = self
                .path
                .clone()
                .ok_or_else(|| anyhow!("standard output takes PNG only"))?;
            return write_exr(set, &path, self.content, band, ctx);
        }
        let w = band.width as usize;
        for y0 in (0..band.height as usize).step_by(ROWS_PER_CHECK) {
            ctx.interrupt.check()?;
            let y1 = (y0 + ROWS_PER_CHECK).min(band.height as usize);
            let part = FrameImage {
                width: band.width,
                height: (y1 - y0) as u32,
                color: band.color[y0 * w..y1 * w].to_vec(),
                depth: band.depth[y0 * w..y1 * w].to_vec(),
            };
            self.write_rows(&part, ctx, ctx.first_row + y0 as u32)?;
        }
        Ok(())
    }

    /// Converts and appends the rows of `part`, which starts at picture row `first_row`.
    fn write_rows(
        &mut self,
        part: &FrameImage,
        ctx: &BandContext<'_>,
        first_row: u32,
    ) -> Result<()> {
        let name = self.name();
        let png = self.path.as_deref().is_none_or(|p| extension(p) == "png");
        let sink = &mut self.sink;
        let result = match self.content {
            Content::Color if png => sink.write_rows(Rows::U8(&part.to_rgba8(true))),
            Content::Color => {
                let data: Vec<f32> = part.color.iter().flatten().copied().collect();
                sink.write_rows(Rows::F32(&data))
            }
            Content::Depth(kind, unit) => {
                let values = depth_values(part, kind, unit, ctx.pose, first_row);
                if png {
                    let gray = depth_png(&values, Path::new(&name))?;
                    sink.write_rows(Rows::U16(&gray))
                } else {
                    sink.write_rows(Rows::F32(&values))
                }
            }
            Content::Normals(space) => {
                let normals = normal_values(part, space, ctx.pose);
                if png {
                    sink.write_rows(Rows::U8(&normals_png(part, &normals)))
                } else {
                    let rgb: Vec<f32> = normals.iter().flatten().copied().collect();
                    sink.write_rows(Rows::F32(&rgb))
                }
            }
            Content::Ids(kind) => {
                let ids = id_values(part, ctx.scene, kind).map_err(|e| anyhow!("{name}: {e}"))?;
                if png {
                    let gray = ids
                        .iter()
                        .map(|&v| u16::try_from(v))
                        .collect::<Result<Vec<u16>, _>>()
                        .map_err(|_| {
                            anyhow!("{name}: an id does not fit a 16-bit PNG; write .exr or .npy")
                        })?;
                    sink.write_rows(Rows::U16(&gray))
                } else {
                    sink.write_rows(Rows::U32(&ids))
                }
            }
        };
        result.map_err(|e| anyhow!("{name}: {e}"))
    }

    /// Ends the file (every row written); standard output gets its PNG now.
    pub fn finish(self) -> Result<()> {
        let name = self.name();
        let result = match self.sink {
            Sink::Exr => Ok(()),
            Sink::File(w) => w.finish().and_then(close_file),
            Sink::Memory(w) => w.finish().and_then(|buffer| {
                let mut out = std::io::stdout().lock();
                out.write_all(buffer.get_ref())?;
                out.flush()
            }),
        };
        result.map_err(|e| anyhow!("{name}: {e}"))
    }
}

impl Sink {
    fn write_rows(&mut self, rows: Rows<'_>) -> std::io::Result<()> {
        match self {
            Sink::File(w) => w.write_rows(rows),
            Sink::Memory(w) => w.write_rows(rows),
            Sink::Exr => Ok(()),
        }
    }
}

/// Normals as 8-bit PNG RGBA: `n * 0.5 + 0.5`, background (depth 1) transparent black.
fn normals_png(frame: &FrameImage, normals: &[[f32; 3]]) -> Vec<u8> {
    let enc = |v: f32| ((v * 0.5 + 0.5).clamp(0.0, 1.0) * 255.0).round() as u8;
    normals
        .iter()
        .zip(&frame.depth)
        .flat_map(|(n, &d)| {
            if d >= 1.0 {
                [0; 4]
            } else {
                [enc(n[0]), enc(n[1]), enc(n[2]), 255]
            }
        })
        .collect()
}

/// An OpenEXR file of `content` from a whole frame.
fn write_exr(
    set: &mut OutputSet,
    path: &Path,
    content: Content,
    frame: &FrameImage,
    ctx: &BandContext<'_>,
) -> Result<()> {
    let (w, h) = (frame.width, frame.height);
    match content {
        Content::Color => {
            let data: Vec<f32> = frame.color.iter().flatten().copied().collect();
            set.write(path, |o| encode_exr_rgba32f(o, w, h, &data))?;
        }
        Content::Depth(kind, unit) => {
            let values = depth_values(frame, kind, unit, ctx.pose, ctx.first_row);
            set.write(path, |o| encode_exr_gray32f(o, w, h, &values))?;
        }
        Content::Normals(space) => {
            let rgb: Vec<f32> = normal_values(frame, space, ctx.pose)
                .iter()
                .flatten()
                .copied()
                .collect();
            set.write(path, |o| encode_exr_rgb32f(o, w, h, &rgb))?;
        }
        Content::Ids(kind) => {
            let ids = id_values(frame, ctx.scene, kind)
                .map_err(|e| anyhow!("{}: {e}", path.display()))?;
            set.write(path, |o| encode_exr_gray_u32(o, w, h, &ids))?;
        }
    }
    Ok(())
}
