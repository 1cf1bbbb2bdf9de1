//! Renders the seed documents' scenes with the programmable pipeline and writes PNGs:
//! `cargo run -p kantele --example seeds -- OUT_DIR`.

use kantele::pipeline::{Renderer, RendererOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| ".".into()));
    std::fs::create_dir_all(&out)?;
    let mut renderer = Renderer::new(800, 600, RendererOptions::default())?;
    for (name, render) in [
        (
            "thesis-cube",
            kantele_testkit::demo::render_thesis_cube as fn(&mut Renderer) -> _,
        ),
        ("exercise", kantele_testkit::demo::render_exercise),
    ] {
        let stats = render(&mut renderer)?;
        let fb = renderer.framebuffer();
        let path = out.join(format!("{name}.png"));
        image::save_buffer(
            &path,
            &fb.read_rgba8(true),
            fb.width(),
            fb.height(),
            image::ColorType::Rgba8,
        )?;
        println!(
            "{}: {} triangles, {:.2} ms",
            path.display(),
            stats.triangles_binned,
            stats.total_time.as_secs_f64() * 1e3
        );
    }
    Ok(())
}
