//! Primitive stage: trivial reject, clipping in homogeneous clip space, and the viewport
//! transform. Takes clip-space vertices with varyings from the vertex stage and hands polygons
//! that are safe to snap (inside the near plane and the guard band) to setup. Lines and points
//! are clipped by [`segment`] and expanded into window-space quads by [`wide`].

pub mod clip;
pub mod segment;
pub mod wide;
