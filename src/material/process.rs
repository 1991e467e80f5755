//! Process limits: what the cut allows the feed V (mm/s) to be, from the engagement of a
//! sample ([`super::cut::Sample`]). Every limit is optional.
//!
//! | limit | bound on V | where |
//! |---|---|---|
//! | chip load f_z (mm/tooth) | `V ≤ f_z · z · n / 60 · k_t(a_e)` | A > 0 |
//! | material removal rate MRR_max (mm³/s) | `V ≤ MRR_max / A` | A > 0 |
//! | spindle power P (W) with specific cutting force k_c (N/mm²) | `V ≤ 1000 P / (k_c A)` | A > 0 |
//! | air-cut feed (mm/s) | `V ≤ air_feed` | A = 0 |
//!
//! with z flutes, spindle speed n (rpm) and the radial chip thinning factor
//! `k_t = D / (2 √(a_e (D − a_e)))` when a_e < D/2 (the chip of a narrow side cut is thinner than
//! the feed per tooth, so the feed may rise until the thickest chip equals f_z), else 1; a plunge
//! takes no thinning. (P in W = N·m/s = 1000 N·mm/s, and the cutting power is k_c·A·V.)
//!
//! Where the tool cuts and no cutting limit is given, the programmed feed stays the cap; where
//! it cuts air and no air feed is given, only the machine's limits apply.

use super::cut::Sample;

pub use crate::base::ProcessLimit;

/// The process limits (each optional) and the spindle speed they need.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct ProcessLimits {
    /// f_z, mm per tooth.
    pub chip_load: Option<f64>,
    /// n, rpm (needed by the chip load; from the program's `S` / `SPINDL/` or an option).
    pub spindle_speed: Option<f64>,
    /// MRR_max, mm³/s.
    pub mrr_max: Option<f64>,
    /// P, W (needs `kc`).
    pub power: Option<f64>,
    /// k_c, N/mm².
    pub kc: Option<f64>,
    /// The feed where the tool cuts air, mm/s.
    pub air_feed: Option<f64>,
}

/// The radial chip thinning factor k_t at radial engagement `ae` of a tool of diameter `d`
/// (module doc): 1 at a_e ≥ D/2, growing without bound as a_e → 0.
pub fn chip_thinning(ae: f64, d: f64) -> f64 {
    if ae >= 0.5 * d || ae <= 0.0 {
        1.0
    } else {
        d / (2.0 * (ae * (d - ae)).sqrt())
    }
}

impl ProcessLimits {
    /// Whether any limit applies where the tool cuts.
    pub fn limits_cutting(&self) -> bool {
        self.chip_load.is_some() || self.mrr_max.is_some() || self.power.is_some()
    }

    /// Whether any limit is given at all.
    pub fn any(&self) -> bool {
        self.limits_cutting() || self.air_feed.is_some()
    }

    /// Every bound on V (mm/s) at a sample, with its limit: the cutting ones where A > 0, the
    /// air feed where A = 0. A tool of diameter `d` with `flutes` teeth.
    pub fn bounds(&self, s: &Sample, d: f64, flutes: u32) -> Vec<(f64, ProcessLimit)> {
        let mut out = Vec::new();
        if s.area > 0.0 {
            if let (Some(fz), Some(n)) = (self.chip_load, self.spindle_speed) {
                let thin = if s.engagement_angle >= 360.0 {
                    1.0
                } else {
                    chip_thinning(s.radial_engagement, d)
                };
                out.push((fz * flutes as f64 * n / 60.0 * thin, ProcessLimit::ChipLoad));
            }
            if let Some(m) = self.mrr_max {
                out.push((m / s.area, ProcessLimit::Mrr));
            }
            if let (Some(p), Some(kc)) = (self.power, self.kc) {
                out.push((1000.0 * p / (kc * s.area), ProcessLimit::Power));
            }
        } else if s.removed <= 0.0 {
            if let Some(a) = self.air_feed {
                out.push((a, ProcessLimit::Air));
            }
        }
        out
    }

    /// The tightest bound on V at a sample, if any.
    pub fn bound(&self, s: &Sample, d: f64, flutes: u32) -> Option<(f64, ProcessLimit)> {
        self.bounds(s, d, flutes)
            .into_iter()
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }
}
