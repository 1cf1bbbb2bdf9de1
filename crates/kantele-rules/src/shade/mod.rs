//! Shading resources: textures, their 8-bit texel format and the samplers that read them; the
//! PBR rules and the specular-glossiness conversion.
pub mod environment;
mod levels;
pub mod pbr;
pub mod sample_lanes;
pub mod sheen;
pub mod spec_gloss;
#[cfg(test)]
mod test_support;
pub mod texel;
mod texel_lanes;
pub mod texture;
pub mod transmission;
