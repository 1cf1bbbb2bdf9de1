//! Cameras attached to nodes (perspective and orthographic).

use glam::Mat4;
use kantele_rules::scene::Camera;

use super::{named, Loader};

impl Loader<'_> {
    /// The camera of a node, if it has a usable (perspective or orthographic) one.
    pub(super) fn camera(&mut self, node: &gltf::Node, world: Mat4) -> Option<Camera> {
        let camera = node.camera()?;
        let name = named(camera.name(), "camera", camera.index());
        let view = world.inverse();
        // The projection's parameters, if valid (the view matrix is checked below for both).
        let projected = match camera.projection() {
            gltf::camera::Projection::Perspective(p) => {
                let ok = p.yfov().is_finite()
                    && p.yfov() > 0.0
                    && p.yfov() < std::f32::consts::PI
                    && p.znear().is_finite()
                    && p.znear() > 0.0
                    && p.zfar().is_none_or(|f| f.is_finite() && f > p.znear())
                    && p.aspect_ratio().is_none_or(|a| a.is_finite() && a > 0.0);
                ok.then(|| Camera {
                    view,
                    yfov: p.yfov(),
                    ymag: None,
                    aspect_ratio: p.aspect_ratio(),
                    znear: p.znear(),
                    zfar: p.zfar(),
                })
            }
            gltf::camera::Projection::Orthographic(o) => {
                // Pixels stay square: `ymag` is kept and the image's aspect decides the width;
                // `xmag / ymag` is the aspect an image takes when no size is given.
                let (xmag, ymag) = (o.xmag().abs(), o.ymag().abs());
                let ok = xmag.is_finite()
                    && xmag > 0.0
                    && ymag.is_finite()
                    && ymag > 0.0
                    && o.znear().is_finite()
                    && o.znear() >= 0.0
                    && o.zfar().is_finite()
                    && o.zfar() > o.znear();
                ok.then(|| Camera {
                    view,
                    yfov: std::f32::consts::FRAC_PI_4,
                    ymag: Some(ymag),
                    aspect_ratio: Some(xmag / ymag),
                    // glTF allows znear = 0 for orthographic cameras; the pipeline's depth
                    // range needs a positive one.
                    znear: o.znear().max(o.zfar() * 1e-6),
                    zfar: Some(o.zfar()),
                })
            }
        };
        match projected {
            Some(camera) if view.is_finite() => Some(camera),
            _ => {
                self.info.warn(format!(
                    "camera '{name}' has invalid parameters or placement; ignored"
                ));
                None
            }
        }
    }
}
