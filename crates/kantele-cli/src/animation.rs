//! Turntables: every view of a scene (`--orbit N`, `--views`) as one animated image, GIF or
//! APNG, written with its sidecar (every frame's camera) once the last frame is rendered.

use std::io::{self, Write};
use std::path::Path;

use kantele::backend::FrameImage;
use kantele_output::output::OutputSet;

use crate::output::extension;

/// File types written as one animation of all views.
pub const ANIMATION_TYPES: &[&str] = &["gif", "apng"];

/// Whether `path` names an animation.
pub fn is_animation(path: &str) -> bool {
    ANIMATION_TYPES.contains(&extension(Path::new(path)).as_str())
}

/// The frames of one animation (8-bit sRGB RGBA, row 0 at the top).
pub struct Animation {
    width: u32,
    height: u32,
    fps: u16,
    frames: Vec<Vec<u8>>,
}

impl Animation {
    /// An empty animation of `width × height` frames at `fps` frames per second.
    pub fn new(width: u32, height: u32, fps: u16) -> Self {
        Self {
            width,
            height,
            fps: fps.max(1),
            frames: Vec::new(),
        }
    }

    /// Appends a rendered frame (must have the animation's size).
    pub fn push(&mut self, frame: &FrameImage) -> io::Result<()> {
        if (frame.width, frame.height) != (self.width, self.height) {
            return Err(io::Error::other(format!(
                "a {}x{} frame in a {}x{} animation: every view needs the same size",
                frame.width, frame.height, self.width, self.height
            )));
        }
        self.frames.push(frame.to_rgba8(true));
        Ok(())
    }

    /// Writes the animation to `path` (.gif or .apng), looping forever, as a file of `set`.
    pub fn write(&self, set: &mut OutputSet, path: &Path) -> anyhow::Result<()> {
        if extension(path) == "gif" {
            set.write(path, |w| self.encode_gif(w))?;
        } else {
            set.write(path, |w| self.encode_apng(w))?;
        }
        Ok(())
    }

    fn encode_apng(&self, out: &mut impl Write) -> io::Result<()> {
        let mut encoder = png::Encoder::new(out, self.width, self.height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder
            .set_animated(self.frames.len() as u32, 0)
            .map_err(io::Error::other)?;
        encoder
            .set_frame_delay(1, self.fps)
            .map_err(io::Error::other)?;
        let mut writer = encoder.write_header().map_err(io::Error::other)?;
        for frame in &self.frames {
            writer.write_image_data(frame).map_err(io::Error::other)?;
        }
        writer.finish().map_err(io::Error::other)
    }

    fn encode_gif(&self, out: &mut impl Write) -> io::Result<()> {
        use image::codecs::gif::{GifEncoder, Repeat};
        let mut encoder = GifEncoder::new_with_speed(out, 10);
        encoder
            .set_repeat(Repeat::Infinite)
            .map_err(io::Error::other)?;
        let delay = image::Delay::from_numer_denom_ms(1000, self.fps as u32);
        for frame in &self.frames {
            let buffer = image::RgbaImage::from_raw(self.width, self.height, frame.clone())
                .ok_or_else(|| io::Error::other("frame buffer of the wrong size"))?;
            encoder
                .encode_frame(image::Frame::from_parts(buffer, 0, 0, delay))
                .map_err(io::Error::other)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(v: f32) -> FrameImage {
        FrameImage {
            width: 4,
            height: 3,
            color: vec![[v, 0.5, 0.0, 1.0]; 12],
            depth: vec![0.5; 12],
        }
    }

    #[test]
    fn apng_and_gif_hold_every_frame() {
        let dir = std::env::temp_dir().join(format!("kantele-anim-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut a = Animation::new(4, 3, 12);
        for i in 0..5 {
            a.push(&frame(i as f32 / 4.0)).unwrap();
        }
        assert!(a
            .push(&FrameImage {
                width: 2,
                ..frame(0.0)
            })
            .is_err());
        let apng = dir.join("t.apng");
        let mut set = OutputSet::new();
        a.write(&mut set, &apng).unwrap();
        set.commit().unwrap();
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&apng).unwrap()));
        let reader = decoder.read_info().unwrap();
        let control = reader.info().animation_control.unwrap();
        assert_eq!(control.num_frames, 5);
        let gif = dir.join("t.gif");
        let mut set = OutputSet::new();
        a.write(&mut set, &gif).unwrap();
        set.commit().unwrap();
        use image::AnimationDecoder;
        let frames = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
            std::fs::File::open(&gif).unwrap(),
        ))
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap();
        assert_eq!(frames.len(), 5);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
