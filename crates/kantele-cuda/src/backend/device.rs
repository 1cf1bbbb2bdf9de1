//! The backend's device resources: the scene's buffers (uploaded at `load`), the frame's
//! working buffers (sized per frame shape and capacities, kept between frames), and the
//! allocation, upload and clearing helpers every buffer goes through.

use std::mem::size_of;
use std::sync::Arc;

use cudarc::driver::{CudaSlice, DevicePtr, DeviceRepr, ValidAsZeroBits};
use kantele_rules::scene::Scene;
use kantele_rules::setup::TriangleSetup;
use kantele_rules::RenderError;

use super::{failed, CudaBackend};
use crate::defines::{MATERIAL_VARYINGS, STATUS_WORDS};
use crate::plan::{Capacities, FrameShape, SCAN_THREADS};
use crate::records::{DrawIssue, SceneView};

/// The scene's data on the device, uploaded once at `load`.
pub(super) struct SceneBuffers {
    pub(super) scene: Arc<Scene>,
    pub(super) records: Vec<crate::records::DrawRecord>,
    /// The draw order `issue` was last written for.
    pub(super) issued_order: Vec<usize>,
    pub(super) issue: CudaSlice<DrawIssue>,
    pub(super) arrays_shape: (u32, u32, u32), // draws, shaded vertices, slots
    pub(super) clear_color: [f32; 4],
    pub(super) ambient: f32,
    pub(super) vertices: CudaSlice<f32>,
    pub(super) indices: CudaSlice<u32>,
    pub(super) draws: CudaSlice<crate::records::DrawRecord>,
    pub(super) textures: CudaSlice<crate::records::TextureRecord>,
    pub(super) levels: CudaSlice<crate::records::LevelRecord>,
    pub(super) texels: CudaSlice<f32>,
}

/// The frame's working buffers, sized for one scene and target size; kept between frames.
pub(super) struct FrameBuffers {
    pub(super) shape: FrameShape,
    pub(super) capacities: Capacities,
    pub(super) mvp: CudaSlice<f32>,
    pub(super) pos_clip: CudaSlice<f32>,
    pub(super) varyings: CudaSlice<f32>,
    pub(super) setups: CudaSlice<u8>,
    pub(super) setup_attrs: CudaSlice<f32>,
    pub(super) slots: CudaSlice<u32>,
    pub(super) counts: CudaSlice<u32>,
    pub(super) offsets: CudaSlice<u32>,
    pub(super) scan_sums: Vec<CudaSlice<u32>>,
    pub(super) tile_start: CudaSlice<u32>,
    pub(super) bins: CudaSlice<u32>,
    pub(super) status: CudaSlice<u64>,
    pub(super) color: CudaSlice<f32>,
    pub(super) depth: CudaSlice<f32>,
    pub(super) rgba8: Option<CudaSlice<u8>>,
    pub(super) ordered: CudaSlice<u32>,
}

impl CudaBackend {
    pub(super) fn alloc<T: DeviceRepr + ValidAsZeroBits>(
        &self,
        len: usize,
        what: &str,
    ) -> Result<CudaSlice<T>, RenderError> {
        self.stream
            .alloc_zeros::<T>(len.max(1))
            .map_err(|e| failed(&format!("allocating {what} ({len} elements)"), e))
    }

    pub(super) fn upload<T: DeviceRepr + Clone>(
        &self,
        data: &[T],
        filler: T,
        what: &str,
    ) -> Result<CudaSlice<T>, RenderError> {
        // Zero-length device buffers are not allowed: upload one filler element instead.
        let one = [filler];
        let data = if data.is_empty() { &one[..] } else { data };
        self.stream
            .clone_htod(data)
            .map_err(|e| failed(&format!("uploading {what}"), e))
    }

    pub(super) fn addr<T>(&self, buffer: &CudaSlice<T>) -> u64 {
        let (ptr, _sync) = buffer.device_ptr(&self.stream);
        ptr
    }

    pub(super) fn zero<T: DeviceRepr + ValidAsZeroBits>(
        &self,
        buffer: &CudaSlice<T>,
    ) -> Result<(), RenderError> {
        let ptr = self.addr(buffer);
        let bytes = buffer.len() * size_of::<T>();
        // SAFETY: `ptr` is the start of `buffer`, which holds `bytes` bytes; the memset is
        // queued on the same stream as every use of the buffer.
        unsafe { cudarc::driver::result::memset_d8_async(ptr, 0, bytes, self.stream.cu_stream()) }
            .map_err(|e| failed("clearing a buffer", e))
    }

    /// (Re)allocates the frame buffers when the shape or capacities changed.
    pub(super) fn prepare_frame(
        &mut self,
        shape: FrameShape,
        capacities: Capacities,
    ) -> Result<(), RenderError> {
        if let Some(f) = &self.frame {
            if f.shape == shape
                && f.capacities == capacities
                && f.rgba8.is_some() == self.resolve_rgba8
            {
                return Ok(());
            }
        }
        self.stream
            .synchronize()
            .map_err(|e| failed("synchronising", e))?;
        self.frame = None;
        let setups_len = shape.slots as usize + capacities.clip as usize;
        let pixels = shape.width as usize * shape.height as usize;
        let cells = shape.matrix_cells() as usize;
        let levels = crate::plan::scan_levels(cells as u64);
        let mut scan_sums = Vec::new();
        for &n in &levels {
            scan_sums
                .push(self.alloc::<u32>(n.div_ceil(SCAN_THREADS as u64) as usize, "scan sums")?);
        }
        let frame = FrameBuffers {
            shape,
            capacities,
            mvp: self.alloc(16 * shape.draws as usize, "matrices")?,
            pos_clip: self.alloc(4 * shape.shaded as usize, "clip positions")?,
            varyings: self.alloc(MATERIAL_VARYINGS * shape.shaded as usize, "varyings")?,
            setups: self.alloc(size_of::<TriangleSetup>() * setups_len, "triangle setups")?,
            setup_attrs: self.alloc(3 * MATERIAL_VARYINGS * setups_len, "setup varyings")?,
            slots: self.alloc(2 * shape.slots as usize, "triangle slots")?,
            counts: self.alloc(cells, "bin counts")?,
            offsets: self.alloc(cells, "bin offsets")?,
            scan_sums,
            tile_start: self.alloc(shape.tiles() as usize + 1, "tile ranges")?,
            bins: self.alloc(capacities.bins as usize, "bins")?,
            status: self.alloc(STATUS_WORDS, "status")?,
            color: self.alloc(4 * pixels, "colour buffer")?,
            depth: self.alloc(pixels, "depth buffer")?,
            rgba8: if self.resolve_rgba8 {
                Some(self.alloc(4 * pixels, "8-bit colour buffer")?)
            } else {
                None
            },
            ordered: self.alloc(1, "ordered triangles")?,
        };
        self.frame = Some(frame);
        Ok(())
    }

    pub(super) fn scene_view(&self, scene: &SceneBuffers) -> SceneView {
        SceneView {
            draws: self.addr(&scene.draws),
            textures: self.addr(&scene.textures),
            levels: self.addr(&scene.levels),
            texels: self.addr(&scene.texels),
        }
    }
}
