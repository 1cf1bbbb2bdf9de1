//! Rasterization (stub).
use std::str::FromStr;

/// How a triangle's pixels are found. Every strategy produces identical coverage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// Every pixel of the bounding box, edge functions evaluated from scratch.
    BoundingBox,
    /// Bounding box scan with edge functions stepped incrementally.
    Incremental,
    /// 8 × 8 blocks classified empty / partial / full.
    Block,
    /// Block or incremental, by bounding-box aspect (0.4–1.6 → blocks).
    Adaptive,
    /// Adaptive, with blocks traversed outwards from a bisector start column.
    #[default]
    Bisector,
}

impl Strategy {
    /// Every strategy.
    pub const ALL: [Strategy; 5] = [
        Strategy::BoundingBox,
        Strategy::Incremental,
        Strategy::Block,
        Strategy::Adaptive,
        Strategy::Bisector,
    ];

    /// The name used on command lines.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::BoundingBox => "bbox",
            Strategy::Incremental => "incremental",
            Strategy::Block => "block",
            Strategy::Adaptive => "adaptive",
            Strategy::Bisector => "bisector",
        }
    }
}

impl FromStr for Strategy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Strategy::ALL
            .into_iter()
            .find(|st| st.name() == s)
            .ok_or_else(|| format!("unknown strategy '{s}' (expected one of: bbox, incremental, block, adaptive, bisector)"))
    }
}
