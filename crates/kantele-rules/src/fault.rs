//! Deliberate faults, compiled in only with the `fault-injection` feature (used by the tests
//! that prove the comparison tools catch real bugs) and switched on at run time by
//! `KANTELE_FAULT=name[,name…]`:
//! - `fill-rule`: use the bottom-right instead of the top-left rule;
//! - `flip-v`: sample textures with `v` mirrored.

use std::sync::OnceLock;

/// A fault that can be planted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// Opposite fill rule.
    FillRule,
    /// Texture V axis mirrored.
    FlipV,
}

/// Whether `fault` is switched on in this process.
pub fn active(fault: Fault) -> bool {
    static ACTIVE: OnceLock<(bool, bool)> = OnceLock::new();
    let (fill_rule, flip_v) = *ACTIVE.get_or_init(|| {
        let list = std::env::var("KANTELE_FAULT").unwrap_or_default();
        let has = |name: &str| list.split(',').any(|f| f.trim() == name);
        (has("fill-rule"), has("flip-v"))
    });
    match fault {
        Fault::FillRule => fill_rule,
        Fault::FlipV => flip_v,
    }
}
