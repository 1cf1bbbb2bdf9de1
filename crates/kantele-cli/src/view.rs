//! `kantele view`: a window (winit + softbuffer) showing a scene rendered every frame, with an
//! orbit camera. Left-drag rotates around the bounding sphere's centre, the wheel zooms, `S`
//! cycles the traversal strategy, `B` toggles cpu / gl, `Esc` / `Q` quits.

use std::num::NonZeroU32;
use std::path::PathBuf;
use std::rc::Rc;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use glam::Vec3;
use kantele::backend::{Backend, FrameImage, FrameView};
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele::raster::Strategy;
use kantele::scene::{Camera, Scene};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::backends::make_backend;
use crate::cli::{BackendKind, ViewArgs};
use crate::output::write_png_rgba8;
use crate::scenes;

/// Orbit camera around a centre.
#[derive(Clone, Copy, Debug)]
struct Orbit {
    center: Vec3,
    radius: f32,
    yaw: f32,
    pitch: f32,
    distance: f32,
    yfov: f32,
}

impl Orbit {
    fn from_scene(scene: &Scene) -> Self {
        let (center, radius) = scene.bounding_sphere().unwrap_or((Vec3::ZERO, 1.0));
        let radius = if radius.is_finite() && radius > 0.0 {
            radius
        } else {
            1.0
        };
        let eye = scene.camera.world_from_eye().transform_point3(Vec3::ZERO);
        let d = eye - center;
        let distance = d.length();
        let (yaw, pitch, distance) = if distance.is_finite() && distance > 1e-6 {
            (
                (d.x).atan2(d.z),
                (d.y / distance).clamp(-1.0, 1.0).asin(),
                distance,
            )
        } else {
            (0.0, 0.3, radius * 3.0)
        };
        Self {
            center,
            radius,
            yaw,
            pitch,
            distance,
            yfov: scene.camera.yfov,
        }
    }

    fn camera(&self) -> Camera {
        let dir = Vec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        );
        let eye = self.center + dir * self.distance;
        Camera {
            view: kantele::camera::look_at(eye, self.center, Vec3::Y),
            yfov: self.yfov,
            ymag: None,
            aspect_ratio: None,
            znear: (self.distance - self.radius).max(self.distance * 1e-3) * 0.5,
            zfar: Some(self.distance + self.radius * 2.0),
        }
    }
}

struct Gfx {
    window: Rc<Window>,
    surface: softbuffer::Surface<Rc<Window>, Rc<Window>>,
}

struct App {
    name: String,
    scene: Arc<Scene>,
    args: ViewArgs,
    strategy: Strategy,
    backend: Box<dyn Backend>,
    backend_kind: BackendKind,
    orbit: Orbit,
    orbiting: bool,
    dragging: bool,
    last_cursor: Option<(f64, f64)>,
    gfx: Option<Gfx>,
    frames: u64,
    fps_frames: u32,
    fps_since: Instant,
    fps: f64,
    last_frame: Option<FrameImage>,
    error: Option<anyhow::Error>,
    /// When the spinning camera last moved.
    last_spin: Option<Instant>,
}

fn pack(c: [f32; 4]) -> u32 {
    let [r, g, b, _] = kantele::color::encode_rgba8(c, true);
    (r as u32) << 16 | (g as u32) << 8 | b as u32
}

impl App {
    fn cpu_backend(&self, strategy: Strategy) -> Result<Box<dyn Backend>> {
        let mut b = CpuBackend::new(CpuOptions {
            threads: self.args.cpu.threads,
            strategy,
            samples: self.args.cpu.samples(),
            target: self.args.cpu.target,
            ..CpuOptions::default()
        })
        .map_err(|e| anyhow!("cpu backend: {e}"))?;
        b.load(self.scene.clone()).map_err(|e| anyhow!("{e}"))?;
        Ok(Box::new(b))
    }

    fn mode(&self) -> String {
        match self.backend_kind {
            BackendKind::Cpu => self.strategy.name().to_string(),
            other => other.name().to_string(),
        }
    }

    fn update_title(&self) {
        if let Some(g) = &self.gfx {
            g.window.set_title(&format!(
                "kantele — {} — {:.1} fps — {}",
                self.name,
                self.fps,
                self.mode()
            ));
        }
    }

    fn cycle_strategy(&mut self) {
        let i = Strategy::ALL
            .iter()
            .position(|s| *s == self.strategy)
            .unwrap_or(0);
        let next = Strategy::ALL[(i + 1) % Strategy::ALL.len()];
        match self.cpu_backend(next) {
            Ok(b) => {
                self.strategy = next;
                if self.backend_kind == BackendKind::Cpu {
                    self.backend = b;
                }
            }
            Err(e) => eprintln!("kantele: warning: {e}"),
        }
        self.update_title();
    }

    fn toggle_backend(&mut self) {
        let result = match self.backend_kind {
            BackendKind::Cpu => {
                make_backend(BackendKind::Gl, &self.args.cpu, false).and_then(|mut b| {
                    b.load(self.scene.clone()).map_err(|e| anyhow!("{e}"))?;
                    Ok((BackendKind::Gl, b))
                })
            }
            _ => self
                .cpu_backend(self.strategy)
                .map(|b| (BackendKind::Cpu, b)),
        };
        match result {
            Ok((kind, b)) => {
                self.backend_kind = kind;
                self.backend = b;
            }
            Err(e) => eprintln!("kantele: warning: cannot switch backend: {e}"),
        }
        self.update_title();
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(());
        };
        let size = gfx.window.inner_size();
        let (w, h) = (
            size.width.min(kantele::MAX_TARGET_SIZE),
            size.height.min(kantele::MAX_TARGET_SIZE),
        );
        let (Some(nw), Some(nh)) = (NonZeroU32::new(w), NonZeroU32::new(h)) else {
            return Ok(());
        };
        if let Some(degrees_per_second) = self.args.spin.filter(|d| d.is_finite()) {
            let now = Instant::now();
            let dt = self.last_spin.map_or(0.0, |t| (now - t).as_secs_f32());
            self.last_spin = Some(now);
            self.orbit.yaw += degrees_per_second.to_radians() * dt;
            self.orbiting = true;
        }
        let camera = if self.orbiting {
            self.orbit.camera()
        } else {
            self.scene.camera
        };
        let view = FrameView::with_camera(&self.scene, &camera, w, h);
        self.backend
            .render(&view)
            .map_err(|e| anyhow!("{}: {e}", self.name))?;
        let frame = self
            .backend
            .read_frame()
            .map_err(|e| anyhow!("{}: {e}", self.name))?;
        if frame.color.len() != w as usize * h as usize {
            bail!(
                "{}: the backend returned a frame of the wrong size",
                self.name
            );
        }
        gfx.surface
            .resize(nw, nh)
            .map_err(|e| anyhow!("window: {e}"))?;
        let mut buffer = gfx
            .surface
            .buffer_mut()
            .map_err(|e| anyhow!("window: {e}"))?;
        for (dst, src) in buffer.iter_mut().zip(&frame.color) {
            *dst = pack(*src);
        }
        buffer.present().map_err(|e| anyhow!("window: {e}"))?;
        self.last_frame = Some(frame);

        self.frames += 1;
        self.fps_frames += 1;
        let elapsed = self.fps_since.elapsed().as_secs_f64();
        if elapsed >= 0.5 {
            self.fps = self.fps_frames as f64 / elapsed;
            self.fps_frames = 0;
            self.fps_since = Instant::now();
            self.update_title();
        }
        if self.args.frames.is_some_and(|n| self.frames >= n) {
            event_loop.exit();
        }
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        let (w, h) = self.args.size.unwrap_or(self.scene.resolution);
        let attributes = Window::default_attributes()
            .with_title(format!("kantele — {} — {}", self.name, self.mode()))
            .with_inner_size(PhysicalSize::new(w.max(1), h.max(1)));
        let result = (|| -> Result<Gfx> {
            let window = Rc::new(
                event_loop
                    .create_window(attributes)
                    .map_err(|e| anyhow!("window: {e}"))?,
            );
            let context =
                softbuffer::Context::new(window.clone()).map_err(|e| anyhow!("window: {e}"))?;
            let surface = softbuffer::Surface::new(&context, window.clone())
                .map_err(|e| anyhow!("window: {e}"))?;
            Ok(Gfx { window, surface })
        })();
        match result {
            Ok(g) => {
                g.window.request_redraw();
                self.gfx = Some(g);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => {
                if let Some(g) = &self.gfx {
                    g.window.request_redraw();
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(event_loop) {
                    self.error = Some(e);
                    event_loop.exit();
                }
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                match event.logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) => event_loop.exit(),
                    Key::Character(c) if c.eq_ignore_ascii_case("q") => event_loop.exit(),
                    Key::Character(c) if c.eq_ignore_ascii_case("s") => self.cycle_strategy(),
                    Key::Character(c) if c.eq_ignore_ascii_case("b") => self.toggle_backend(),
                    _ => {}
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = state == ElementState::Pressed;
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let (true, Some((x0, y0))) = (self.dragging, self.last_cursor) {
                    let (dx, dy) = ((position.x - x0) as f32, (position.y - y0) as f32);
                    self.orbiting = true;
                    self.orbit.yaw -= dx * 0.01;
                    self.orbit.pitch = (self.orbit.pitch + dy * 0.01).clamp(-1.5, 1.5);
                }
                self.last_cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.orbiting = true;
                let min = self.orbit.radius * 1e-3;
                self.orbit.distance = (self.orbit.distance * 0.9f32.powf(steps)).max(min);
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }
}

/// Runs `kantele view`.
pub fn run(args: ViewArgs) -> Result<()> {
    let inputs = scenes::inputs(&args.input)?;
    if inputs.len() != 1 {
        bail!("view shows one scene ({} given)", inputs.len());
    }
    let input = &inputs[0];
    if let Some(p) = &args.screenshot {
        if crate::output::extension(p) != "png" {
            bail!("{}: the screenshot must be a .png file", p.display());
        }
    }
    let set = |v: &str| std::env::var_os(v).is_some_and(|s| !s.is_empty());
    if !set("DISPLAY") && !set("WAYLAND_DISPLAY") && !set("WAYLAND_SOCKET") {
        bail!("view: no display to open a window on (neither DISPLAY nor WAYLAND_DISPLAY is set)");
    }
    let loaded = input.load()?;
    let mut warnings = scenes::Warnings::default();
    warnings.report(&loaded, |w| eprintln!("{w}"));
    let scene = Arc::new(loaded.scene);
    let strategy = args.cpu.strategy.unwrap_or_default();
    let mut backend = make_backend(args.backend, &args.cpu, false)?;
    backend
        .load(scene.clone())
        .map_err(|e| anyhow!("{}: {e}", input.label()))?;
    let screenshot: Option<PathBuf> = args.screenshot.clone();

    let event_loop = EventLoop::new().map_err(|e| anyhow!("view: cannot open a window: {e}"))?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        name: input.stem(),
        orbit: Orbit::from_scene(&scene),
        scene,
        strategy,
        backend_kind: args.backend,
        backend,
        args,
        orbiting: false,
        dragging: false,
        last_cursor: None,
        last_spin: None,
        gfx: None,
        frames: 0,
        fps_frames: 0,
        fps_since: Instant::now(),
        fps: 0.0,
        last_frame: None,
        error: None,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("view: {e}"))?;
    if let Some(e) = app.error.take() {
        return Err(e);
    }
    if let Some(p) = screenshot {
        let frame = app.last_frame.as_ref().ok_or_else(|| {
            anyhow!(
                "{}: no frame was rendered, so there is nothing to save",
                p.display()
            )
        })?;
        write_png_rgba8(&p, frame.width, frame.height, &frame.to_rgba8(true))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pack_is_0rgb() {
        assert_eq!(pack([1.0, 0.0, 0.0, 1.0]), 0x00ff_0000);
        assert_eq!(pack([0.0, 1.0, 0.0, 0.0]), 0x0000_ff00);
        assert_eq!(pack([0.0, 0.0, 1.0, 1.0]), 0x0000_00ff);
    }

    #[test]
    fn orbit_starts_at_the_scene_camera() {
        let scene = Scene::default();
        let o = Orbit::from_scene(&scene);
        let eye = o.camera().world_from_eye().transform_point3(Vec3::ZERO);
        let want = scene.camera.world_from_eye().transform_point3(Vec3::ZERO);
        assert!((eye - want).length() < 1e-3, "{eye} vs {want}");
    }
}
