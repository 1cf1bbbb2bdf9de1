//! Shading resources: textures, their 8-bit texel format and the samplers that read them.
pub(crate) mod sample_lanes;
pub mod texel;
mod texel_lanes;
pub mod texture;
