//! Shading resources: textures, their 8-bit texel format and the samplers that read them.
mod levels;
pub mod sample_lanes;
pub mod texel;
mod texel_lanes;
pub mod texture;
