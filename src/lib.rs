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
//! a convex problem, discretised at stations and solved as a second-order cone program with
//! Clarabel.
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
//! Units: mm, degrees, seconds in every file; feeds in machine files in mm/s; APT feeds per
//! minute as the format defines.

pub mod cli;
pub mod compare;
pub mod constraints;
pub mod error;
pub mod files;
pub mod geometry;
pub mod interpolate;
pub mod kinematics;
pub mod machine;
pub mod material;
pub mod motion;
pub mod optimize;
pub mod report;
pub mod schedule;
pub mod solver;
pub mod sweep;
pub mod toolpath;
pub mod verify;
pub mod writers;
