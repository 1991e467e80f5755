//! # feedopt — time-optimal feedrate along CNC toolpaths
//!
//! feedopt computes the fastest feed profile along a toolpath that keeps every axis of a real
//! machine within its velocity and acceleration limits.
//!
//! ## The problem solved
//!
//! A toolpath gives tool-tip positions P(u) and tool orientations O(u) along one parameter u.
//! Through the machine's inverse kinematics every axis q follows q(u). With b = u̇² the axes move
//! as (seed 000, "the coordinated principle of 5-axis NC", eq. 28–39, written in u)
//!
//! ```text
//! q̇ = q'(u) √b,     q̈ = q''(u) b + q'(u) ü,     ü = ½ db/du,
//! ```
//!
//! where, on a moving path, q' and q'' are the *effective tangent* t_q and *effective curvature*
//! K_q scaled by |P'|. Every limit is therefore linear in b and its derivative:
//!
//! ```text
//! minimise    T = ∫ du / √b(u)                                   (eq. 40–43)
//! subject to  q'(u)² b(u) ≤ v_q²                                 (axis velocity)
//!             a_q,min ≤ q''(u) b(u) + ½ q'(u) b'(u) ≤ a_q,max    (axis acceleration)
//!             |P'(u)|² b(u) ≤ F(u)²                              (programmed / maximum feed)
//!             b = 0 at both ends of every rest-to-rest span
//! ```
//!
//! a convex problem. Discretised at stations u_0 < u_1 < … < u_N with b linear between them
//! (ü constant on each interval), the cycle time is exact in closed form and every limit is a
//! linear row on the b_k at the interval's ends:
//!
//! ```text
//! minimise    Σ_k 2 Δu_k / (√b_k + √b_{k+1})                    (eq. 43)
//! subject to  b_k ≤ b_max,k                                      (velocity and feed rows)
//!             a_q,min ≤ q''_k b_k + q'_k (b_{k+1} − b_k)/(2Δu_k) ≤ a_q,max   (at both ends)
//!             b_0, b_N given                                     (rest, or a start/end feed)
//! ```
//!
//! a second-order cone program ([`solver::clarabel`] states its cones), solved with Clarabel;
//! the exact O(N) reachability pass ([`solver::reach`]) solves the same rows greedily, and with
//! jerk limits a sequence of such programs ([`solver::jerk`]). Stations are refined until the
//! cycle time converges, and every schedule is re-simulated at the servo period before it is
//! returned ([`verify`]).
//!
//! ## Pipeline
//!
//! Each stage is a module with one job and plain data between stages:
//! [`toolpath`] (readers) → [`geometry`] (spans, splines) → [`kinematics`] (q, t_q, K_q) →
//! [`material`] (optional: dexel stock, engagement, process feed caps) → [`constraints`] (rows on b) → [`solver`] (Clarabel; the O(N) reachability pass; the
//! jerk-limited SCP) → [`schedule`] (time, eq. 43, through the [`motion`] laws between
//! stations) → [`verify`] (re-simulation at the servo period) → [`report`] (summary) and
//! [`writers`] (JSON, CSV, G-code, plots). [`optimize::optimize`] runs them all (and
//! [`optimize::optimize_joint`] for joint-space paths). On top: [`interpolate`] (setpoints at
//! the servo period), [`compare`] (schedules side by side) and [`sweep`] (constraint studies).
//!
//! With jerk limits in the machine file the schedule also keeps every axis's jerk
//! q⃛ = √b (q‴ b + (3/2) q″ b′ + (1/2) q′ b″) within them: not convex in b, solved by sequential
//! convex programming ([`solver::jerk`]).
//!
//! ```no_run
//! use feedopt::{machine::Machine, optimize, toolpath};
//! let machine = Machine::from_file("problems/seed_head_head/machine.json".as_ref())?;
//! let path = toolpath::read("problems/seed_head_head/impeller_blade.cls".as_ref())?;
//! let solution = optimize::optimize(&machine, &path, &optimize::Options::default())?;
//! println!("cycle time {:.3} s", solution.schedule.cycle_time);
//! # Ok::<(), feedopt::error::Error>(())
//! ```
//!
//! Every entry point checks its inputs before any work: an option out of range is
//! [`Error::InvalidOption`](error::Error::InvalidOption) naming the field (the ranges are listed
//! in [`validate`]), a machine built in code is checked as a machine file is
//! ([`Machine::validate`](machine::Machine::validate)). Diagnostics are `tracing` events (DEBUG:
//! refinement rounds and SCP iterates; TRACE: Clarabel's log); install a subscriber to see them.
//! `examples/` holds a solve of an APT file, a constraint study, a user's own kinematics and a
//! joint-space path.
//!
//! ## Cargo features
//!
//! The front ends are features, on by default: `cli` (the `feedopt` binary and [`cli`]; clap,
//! tracing-subscriber), `plot` (SVG plots, [`writers::plot`]; plotters) and `progress` (progress
//! bars, [`progress`]; indicatif). `cargo build --no-default-features --lib` builds the library
//! with none of them.
//!
//! Units: mm, degrees, seconds in every file; feeds in machine files in mm/s; APT feeds per
//! minute as the format defines.

#![warn(missing_docs)]

pub mod base;
#[cfg(feature = "cli")]
pub mod cli;
pub mod compare;
// Being edited on other branches (the dexel stage, the readers, the jerk-limited refinement):
// their public items are documented once those land.
#[allow(missing_docs)]
pub mod constraints;
pub mod error;
pub mod files;
pub mod geometry;
pub mod interpolate;
pub mod kinematics;
pub mod machine;
pub mod material;
pub mod motion;
#[allow(missing_docs)]
pub mod optimize;
mod parallel;
#[cfg(feature = "progress")]
pub mod progress;
pub mod report;
pub mod schedule;
pub mod solver;
pub mod sweep;
#[allow(missing_docs)]
pub mod toolpath;
pub mod validate;
pub mod verify;
pub mod writers;

/// A small deterministic generator of numbers in [0, 1) for the unit tests (a linear
/// congruential generator: no dependency needed for a test's random cases).
#[cfg(test)]
pub(crate) fn test_rng(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}
