//! Each distinct span problem solved once.
//!
//! Real programs repeat moves: a drilling cycle plunges, feeds and retracts the same way at
//! every hole; a pattern of pockets, or parts on a fixture, repeats a whole sequence at other
//! places. On a machine whose limits do not depend on where the axes stand (every linear axis;
//! a rotary one turning by the same angles), the same move elsewhere is the same problem for
//! the solver: the same stations, bounds and axis derivatives. The solvers are deterministic
//! functions of what they read, so the answer of one such problem is the answer of all.
//!
//! The key is the exact bits of every input of the solve: the span problem
//! ([`SpanProblem::fingerprint`]), the jerk data ([`JerkData::fingerprint`]), the starting
//! profiles, and the solver's settings. Two keys are compared word by word, never by a hash
//! alone, so a reused answer is exactly the one a solve would give; `Options::reuse_spans`
//! turns this off (a test compares both ways bit for bit).
//!
//! Memory is bounded before it grows: spans of more than [`MAX_STATIONS`] stations are not
//! kept (long spans seldom repeat), nor anything once the kept keys and profiles reach
//! [`MAX_WORDS`] words (64 MB).

use std::collections::HashMap;
use std::sync::Mutex;

use crate::constraints::SpanProblem;
use crate::solver::jerk::{JerkOptions, Warm};
use crate::solver::{SolverSettings, SpanSolution, Status};

/// Spans longer than this (stations) are solved without keeping their answer: long spans
/// seldom repeat, and a jerk-limited key carries some 160 words per interval (every
/// collocation point's derivatives), 6 MB at this length.
pub const MAX_STATIONS: usize = 5_000;

/// Keys and profiles kept, 8-byte words, at most.
pub const MAX_WORDS: usize = 1 << 23;

/// A key: hashed by its length and at most [`HASHED_WORDS`] words spread over it (hashing
/// every word of a long span's key cost 6 % of a drilling program's solve), compared whole.
#[derive(Debug, PartialEq, Eq)]
pub(crate) struct Key(Vec<u64>);

/// Words of a key that its hash reads, at most.
const HASHED_WORDS: usize = 64;

impl std::hash::Hash for Key {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        let n = self.0.len();
        state.write_usize(n);
        let stride = n.div_ceil(HASHED_WORDS).max(1);
        // The last words too: the jerk data and the starting profile end the key.
        for w in self
            .0
            .iter()
            .step_by(stride)
            .chain(self.0.iter().rev().take(8))
        {
            state.write_u64(*w);
        }
    }
}

/// The answers of the span problems solved so far in one solve.
#[derive(Debug)]
pub(crate) struct Reuse {
    enabled: bool,
    inner: Mutex<Inner>,
}

#[derive(Debug, Default)]
struct Inner {
    answers: HashMap<Key, SpanSolution>,
    words: usize,
    hits: usize,
}

impl Reuse {
    pub fn new(enabled: bool) -> Reuse {
        Reuse {
            enabled,
            inner: Mutex::new(Inner::default()),
        }
    }

    /// The key of a solve of `p` with `settings` (and `jerk`, for a jerk-limited one) from the
    /// starting profile `greedy` (and `warm`), `more` appending what else it reads (the jerk
    /// data); `None` when answers are not kept (turned off, or `p` too long).
    pub fn key(
        &self,
        p: &SpanProblem,
        settings: &SolverSettings,
        jerk: Option<&JerkOptions>,
        greedy: &SpanSolution,
        warm: Option<&Warm>,
        more: impl FnOnce(&mut Vec<u64>),
    ) -> Option<Key> {
        if !self.enabled || p.u.len() > MAX_STATIONS {
            return None;
        }
        let mut key = Vec::new();
        settings_words(settings, &mut key);
        match jerk {
            Some(j) => {
                key.push(1);
                jerk_words(j, &mut key);
            }
            None => key.push(0),
        }
        p.fingerprint(&mut key);
        profile_words(
            &greedy.b,
            greedy.a.as_deref(),
            greedy.slopes.as_deref(),
            &mut key,
        );
        key.push(status_word(greedy.status));
        match warm {
            Some(w) => {
                key.push(1);
                profile_words(&w.b, Some(&w.a), Some(&w.slopes), &mut key);
                key.extend(w.fresh.iter().map(|&f| u64::from(f)));
                key.push(u64::from(w.local));
            }
            None => key.push(0),
        }
        more(&mut key);
        Some(Key(key))
    }

    /// The answer kept under `key` (with no solver work counted: its iterations and solve
    /// time were counted with the first solve), else `solve()`'s, kept under `key` while the
    /// memory bound allows. Without a key, `solve()`. An error is never kept (its message
    /// names the span it came from).
    pub fn answer(
        &self,
        key: Option<Key>,
        solve: impl FnOnce() -> crate::error::Result<SpanSolution>,
    ) -> crate::error::Result<SpanSolution> {
        let Some(key) = key else { return solve() };
        {
            let mut inner = self.inner.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(kept) = inner.answers.get(&key) {
                let mut sol = kept.clone();
                inner.hits += 1;
                sol.iterations = 0;
                sol.solve_time = 0.0;
                return Ok(sol);
            }
        }
        // Solved outside the lock: spans are solved in parallel (two that pose the same
        // problem at once are both solved, to the same answer).
        let sol = solve()?;
        let words = key.0.len()
            + sol.b.len()
            + sol.a.as_ref().map_or(0, Vec::len)
            + 2 * sol.slopes.as_ref().map_or(0, Vec::len)
            + 2 * sol.ends.as_ref().map_or(0, Vec::len);
        let mut inner = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        if inner.words + words <= MAX_WORDS && !inner.answers.contains_key(&key) {
            inner.words += words;
            inner.answers.insert(key, sol.clone());
        }
        Ok(sol)
    }

    /// Solves answered from a kept answer so far.
    pub fn hits(&self) -> usize {
        self.inner.lock().unwrap_or_else(|e| e.into_inner()).hits
    }
}

fn settings_words(s: &SolverSettings, out: &mut Vec<u64>) {
    let SolverSettings {
        max_iter,
        tol_gap,
        tol_feas,
        iterative_refinement,
        window,
        threads,
        time_limit,
    } = *s;
    out.extend([
        u64::from(max_iter),
        tol_gap.to_bits(),
        tol_feas.to_bits(),
        u64::from(iterative_refinement),
        window as u64,
        // The windows of a jerk-limited span depend on the threads (their number, not who
        // runs them): 0 is as many as the machine has, the same all through one solve.
        threads as u64,
        time_limit.to_bits(),
    ]);
}

fn jerk_words(j: &JerkOptions, out: &mut Vec<u64>) {
    let JerkOptions {
        convergence,
        max_iterations,
        objective,
        window,
        closed_form,
        lp_solver,
    } = *j;
    out.extend([
        convergence.to_bits(),
        max_iterations as u64,
        objective as u64,
        window as u64,
        u64::from(closed_form),
        lp_solver as u64,
    ]);
}

fn profile_words(b: &[f64], a: Option<&[f64]>, slopes: Option<&[[f64; 2]]>, out: &mut Vec<u64>) {
    out.push(b.len() as u64);
    out.extend(b.iter().map(|x| x.to_bits()));
    match a {
        Some(a) => {
            out.push(a.len() as u64);
            out.extend(a.iter().map(|x| x.to_bits()));
        }
        None => out.push(u64::MAX),
    }
    match slopes {
        Some(s) => {
            out.push(s.len() as u64);
            out.extend(s.iter().flatten().map(|x| x.to_bits()));
        }
        None => out.push(u64::MAX),
    }
}

fn status_word(s: Status) -> u64 {
    match s {
        Status::Optimal => 0,
        Status::AlmostOptimal => 1,
        Status::Greedy => 2,
    }
}
