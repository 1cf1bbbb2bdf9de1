//! The render target: the single-sample framebuffer frames are read from, the multisampled one
//! colour frames are drawn into at 4× or 8×, their creation for a view's size and format, and the
//! resolve between them; and the one-sample float framebuffer a frame's transmission backdrop
//! is drawn into and read back from.

use glow::HasContext;
use kantele_rules::multisample::SampleCount;
use kantele_rules::RenderError;

use crate::{backend_error, unsupported, GlBackend};

/// The render target: a framebuffer with a colour and a depth renderbuffer.
pub(crate) struct Target {
    pub(crate) framebuffer: glow::Framebuffer,
    pub(crate) color: glow::Renderbuffer,
    pub(crate) depth: glow::Renderbuffer,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) fast: bool,
    /// The multisampled framebuffer colour frames are drawn into before they are resolved
    /// into `framebuffer` (`None` at 1×).
    pub(crate) multisample: Option<MultisampleTarget>,
}

/// A multisampled framebuffer of the target's size and formats.
pub(crate) struct MultisampleTarget {
    pub(crate) framebuffer: glow::Framebuffer,
    pub(crate) color: glow::Renderbuffer,
    pub(crate) depth: glow::Renderbuffer,
    pub(crate) samples: SampleCount,
}

/// Depth format of both framebuffers.
const DEPTH_FORMAT: u32 = glow::DEPTH_COMPONENT32F;

/// Allocates `renderbuffer` as `width × height` of `format` with `samples` per pixel and attaches
/// it to the bound framebuffer at `attachment` (the renderbuffer binding is left unbound).
///
/// # Safety
/// `gl` must be current on this thread, with a framebuffer bound that owns `renderbuffer`.
unsafe fn attach_renderbuffer(
    gl: &glow::Context,
    renderbuffer: glow::Renderbuffer,
    attachment: u32,
    format: u32,
    samples: SampleCount,
    (width, height): (i32, i32),
) {
    // SAFETY: the caller guarantees a current context and a bound framebuffer; `renderbuffer`
    // is a live object of that context.
    unsafe {
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(renderbuffer));
        if samples.is_multisampled() {
            let count = samples.count() as i32;
            gl.renderbuffer_storage_multisample(glow::RENDERBUFFER, count, format, width, height);
        } else {
            gl.renderbuffer_storage(glow::RENDERBUFFER, format, width, height);
        }
        gl.framebuffer_renderbuffer(
            glow::FRAMEBUFFER,
            attachment,
            glow::RENDERBUFFER,
            Some(renderbuffer),
        );
        gl.bind_renderbuffer(glow::RENDERBUFFER, None);
    }
}

impl GlBackend {
    /// Creates (or re-creates) the framebuffer for the view's size, the selected format and
    /// `samples` per pixel.
    pub(crate) fn ensure_target(
        &mut self,
        width: u32,
        height: u32,
        samples: SampleCount,
    ) -> Result<(), RenderError> {
        if let Some(t) = &self.target {
            let target_samples = t
                .multisample
                .as_ref()
                .map_or(SampleCount::X1, |m| m.samples);
            if t.width == width
                && t.height == height
                && t.fast == self.fast_target
                && target_samples == samples
            {
                return Ok(());
            }
        }
        self.delete_target();
        let fast = self.fast_target;
        let gl = &self.gl;
        // SAFETY: `gl` is current on this thread; the objects are created here and attached
        // to the framebuffer created here.
        let target = unsafe {
            let max = gl.get_parameter_i32(glow::MAX_RENDERBUFFER_SIZE);
            let mut dims = [0i32; 2];
            gl.get_parameter_i32_slice(glow::MAX_VIEWPORT_DIMS, &mut dims);
            if width as i64 > max.min(dims[0]) as i64 || height as i64 > max.min(dims[1]) as i64 {
                return Err(unsupported(format!(
                    "target {width}x{height} exceeds the driver's limits (renderbuffer {max}, viewport {}x{})",
                    dims[0], dims[1]
                )));
            }
            let framebuffer = gl.create_framebuffer().map_err(backend_error)?;
            let color = gl.create_renderbuffer().map_err(backend_error)?;
            let depth = gl.create_renderbuffer().map_err(backend_error)?;
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(framebuffer));
            let color_format = if fast { glow::RGBA8 } else { glow::RGBA32F };
            let size = (width as i32, height as i32);
            let single = SampleCount::X1;
            attach_renderbuffer(
                gl,
                color,
                glow::COLOR_ATTACHMENT0,
                color_format,
                single,
                size,
            );
            attach_renderbuffer(
                gl,
                depth,
                glow::DEPTH_ATTACHMENT,
                DEPTH_FORMAT,
                single,
                size,
            );
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            let mut target = Target {
                framebuffer,
                color,
                depth,
                width,
                height,
                fast,
                multisample: None,
            };
            if status != glow::FRAMEBUFFER_COMPLETE {
                self.target = Some(target);
                self.delete_target();
                return Err(backend_error(format!(
                    "framebuffer {width}x{height} incomplete (status 0x{status:04X})"
                )));
            }
            if samples.is_multisampled() {
                let ms = MultisampleTarget {
                    framebuffer: gl.create_framebuffer().map_err(backend_error)?,
                    color: gl.create_renderbuffer().map_err(backend_error)?,
                    depth: gl.create_renderbuffer().map_err(backend_error)?,
                    samples,
                };
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(ms.framebuffer));
                attach_renderbuffer(
                    gl,
                    ms.color,
                    glow::COLOR_ATTACHMENT0,
                    color_format,
                    samples,
                    size,
                );
                attach_renderbuffer(
                    gl,
                    ms.depth,
                    glow::DEPTH_ATTACHMENT,
                    DEPTH_FORMAT,
                    samples,
                    size,
                );
                let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
                target.multisample = Some(ms);
                if status != glow::FRAMEBUFFER_COMPLETE {
                    self.target = Some(target);
                    self.delete_target();
                    return Err(unsupported(format!(
                        "{samples}x multisampled framebuffer {width}x{height} incomplete \
                         (status 0x{status:04X})"
                    )));
                }
            }
            target
        };
        self.target = Some(target);
        self.last_pass = None;
        self.check("creating the framebuffer")
    }

    pub(crate) fn delete_target(&mut self) {
        if let Some(t) = self.target.take() {
            // SAFETY: `gl` is current on this thread and the objects are ours.
            unsafe {
                self.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
                self.gl.delete_framebuffer(t.framebuffer);
                self.gl.delete_renderbuffer(t.color);
                self.gl.delete_renderbuffer(t.depth);
                if let Some(ms) = t.multisample {
                    self.gl.delete_framebuffer(ms.framebuffer);
                    self.gl.delete_renderbuffer(ms.color);
                    self.gl.delete_renderbuffer(ms.depth);
                }
            }
        }
        self.last_pass = None;
        self.multisampled_view = None;
    }

    /// Resolves the multisampled colour into the single-sample target (`glBlitFramebuffer`).
    pub(crate) fn resolve(&self) -> Result<(), RenderError> {
        let target = self.target.as_ref().expect("target was created");
        let Some(ms) = &target.multisample else {
            return Ok(());
        };
        let (w, h) = (target.width as i32, target.height as i32);
        // SAFETY: `gl` is current on this thread; both framebuffers are ours, complete and of
        // the same size and colour format.
        unsafe {
            let gl = &self.gl;
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(ms.framebuffer));
            gl.read_buffer(glow::COLOR_ATTACHMENT0);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(target.framebuffer));
            gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]);
            gl.blit_framebuffer(
                0,
                0,
                w,
                h,
                0,
                0,
                w,
                h,
                glow::COLOR_BUFFER_BIT,
                glow::NEAREST,
            );
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            gl.finish();
        }
        self.check("resolving the multisampled frame")
    }
}

/// A one-sample `GL_RGBA32F` framebuffer with its depth, for a frame's backdrop.
pub(crate) struct BackdropTarget {
    pub(crate) framebuffer: glow::Framebuffer,
    color: glow::Renderbuffer,
    depth: glow::Renderbuffer,
}

impl GlBackend {
    /// A `width × height` [`BackdropTarget`] (the colour format of the reference target,
    /// whatever [`GlBackend::set_fast_target`] selects, and the target's depth format).
    pub(crate) fn create_backdrop_target(
        &self,
        width: u32,
        height: u32,
    ) -> Result<BackdropTarget, RenderError> {
        let gl = &self.gl;
        // SAFETY: `gl` is current on this thread; the objects are created here and attached
        // to the framebuffer created here.
        unsafe {
            let target = BackdropTarget {
                framebuffer: gl.create_framebuffer().map_err(backend_error)?,
                color: gl.create_renderbuffer().map_err(backend_error)?,
                depth: gl.create_renderbuffer().map_err(backend_error)?,
            };
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(target.framebuffer));
            let size = (width as i32, height as i32);
            let single = SampleCount::X1;
            let color = (target.color, glow::COLOR_ATTACHMENT0, glow::RGBA32F);
            let depth = (target.depth, glow::DEPTH_ATTACHMENT, DEPTH_FORMAT);
            for (renderbuffer, attachment, format) in [color, depth] {
                attach_renderbuffer(gl, renderbuffer, attachment, format, single, size);
            }
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            if status != glow::FRAMEBUFFER_COMPLETE {
                self.delete_backdrop_target(target);
                return Err(backend_error(format!(
                    "backdrop framebuffer {width}x{height} incomplete (status 0x{status:04X})"
                )));
            }
            Ok(target)
        }
    }

    /// Deletes a [`BackdropTarget`].
    pub(crate) fn delete_backdrop_target(&self, target: BackdropTarget) {
        // SAFETY: `gl` is current on this thread and the objects are ours, deleted once (the
        // target is consumed).
        unsafe {
            self.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            self.gl.delete_framebuffer(target.framebuffer);
            self.gl.delete_renderbuffer(target.color);
            self.gl.delete_renderbuffer(target.depth);
        }
    }

    /// The `width × height` RGBA float colour of `framebuffer`'s first attachment, GL's row 0
    /// first (the image's top row under the y-flipped projection): a frame's or a backdrop's.
    pub(crate) fn read_color(
        &self,
        framebuffer: glow::Framebuffer,
        width: u32,
        height: u32,
    ) -> Result<Vec<[f32; 4]>, RenderError> {
        let mut color = vec![0u8; width as usize * height as usize * 16];
        // SAFETY: `gl` is current on this thread; the framebuffer is ours; the buffer holds
        // exactly width × height RGBA f32 values with PACK_ALIGNMENT 4 and no row length,
        // which is what glReadPixels writes for this format.
        unsafe {
            let gl = &self.gl;
            gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(framebuffer));
            gl.read_buffer(glow::COLOR_ATTACHMENT0);
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
            gl.pixel_store_i32(glow::PACK_ROW_LENGTH, 0);
            gl.read_pixels(
                0,
                0,
                width as i32,
                height as i32,
                glow::RGBA,
                glow::FLOAT,
                glow::PixelPackData::Slice(Some(&mut color)),
            );
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, None);
        }
        self.check("reading colour back")?;
        let float = |b: &[u8]| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]);
        Ok(color
            .chunks_exact(16)
            .map(|p| [0, 4, 8, 12].map(|o| float(&p[o..o + 4])))
            .collect())
    }
}
