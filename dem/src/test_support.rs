//! Helpers shared by the engine's unit tests.

/// The next number of a 64-bit linear congruential generator of state `state` (Knuth's MMIX
/// multiplier and increment), uniform in `[0, 1)`: the state's 53 high bits over `2⁵³`.
pub(crate) fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    ((*state >> 11) as f64) / ((1u64 << 53) as f64)
}
