//! Interpreting: the modal state and the moves each block makes.

use nalgebra::Vector3;
use std::path::Path;

use super::dialect::*;
use super::lexer::{Item, Num};
use super::*;
use crate::error::{Error, Result};
use crate::toolpath::{ClPoint, Feed, MM_PER_INCH, Toolpath, Warning};

// ---------------------------------------------------------------------------------------------
// Interpreting
// ---------------------------------------------------------------------------------------------

/// The words of one block, sorted by meaning.
#[derive(Debug, Default)]
struct Block {
    axes: [Option<Num>; 6],
    centre: [Option<Num>; 3],
    vector: [Option<f64>; 3],
    radius: Option<Num>,
    turns: Option<f64>,
    extra_turns: Option<f64>,
    feed: Option<f64>,
    /// Codes and keywords in the order written, with their text.
    actions: Vec<(String, Action)>,
}

/// The modal G94 feed.
#[derive(Debug, Clone, Copy)]
struct ModalFeed {
    /// Linear feed, mm/min.
    mm_per_min: f64,
    /// F as written (degrees per minute on rotary-only moves).
    raw: f64,
}

const AXIS_NAMES: [char; 6] = ['X', 'Y', 'Z', 'A', 'B', 'C'];

pub(super) struct Interpreter<'a> {
    spec: &'a DialectSpec,
    source: &'a Path,
    units: Units,
    feed_units: Units,
    distance: Distance,
    arc_distance: Distance,
    plane: Plane,
    feed_mode: FeedMode,
    feed: Option<ModalFeed>,
    motion: Option<Motion>,
    tcp: Tcp,
    /// Modal position: X Y Z in mm, A B C in degrees.
    pos: [f64; 6],
    /// X Y Z set by an absolute word.
    known: [bool; 3],
    unknown_warned: [bool; 3],
    vector: Vector3<f64>,
    saw_rotary: bool,
    /// A warning about motion outside TCP mode was given for the current stretch.
    non_tcp_warned: bool,
    pub(super) ended: bool,
    points: Vec<ClPoint>,
    warnings: Vec<Warning>,
}

impl<'a> Interpreter<'a> {
    pub(super) fn new(spec: &'a DialectSpec, source: &'a Path) -> Self {
        Interpreter {
            spec,
            source,
            units: Units::Mm,
            feed_units: Units::Mm,
            distance: Distance::Absolute,
            arc_distance: Distance::Incremental,
            plane: Plane::Xy,
            feed_mode: FeedMode::PerMinute,
            feed: None,
            motion: spec.initial_motion,
            tcp: Tcp::Off,
            pos: [0.0; 6],
            known: [false; 3],
            unknown_warned: [false; 3],
            vector: Vector3::new(0.0, 0.0, 1.0),
            saw_rotary: false,
            non_tcp_warned: false,
            ended: false,
            points: Vec::new(),
            warnings: Vec::new(),
        }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::parse(self.source, line, message)
    }

    pub(super) fn warn(&mut self, line: usize, message: impl Into<String>) {
        self.warnings.push(Warning {
            line,
            message: message.into(),
        });
    }

    pub(super) fn finish(mut self, last_line: usize) -> Result<Toolpath> {
        if self.points.is_empty() {
            return Err(self.error(last_line.max(1), "no motion blocks"));
        }
        if !self.saw_rotary {
            for p in &mut self.points {
                p.rotary = None;
            }
        }
        Ok(Toolpath {
            source: self.source.to_path_buf(),
            points: self.points,
            warnings: self.warnings,
        })
    }

    /// Sorts a block's words, warning about unknown ones.
    fn collect(&mut self, line: usize, items: Vec<Item>) -> Result<Block> {
        let mut block = Block::default();
        let name = self.spec.name;
        for item in items {
            let (text, address, num) = match item {
                Item::Word { text, address, num } => (text, address, num),
                Item::Keyword { text, action } => {
                    block.actions.push((text, action));
                    continue;
                }
                Item::Skipped => continue,
                Item::Unknown { text } => {
                    self.warn(
                        line,
                        format!("unknown word `{text}` (not a {name} word): ignored"),
                    );
                    continue;
                }
            };
            let source = self.source;
            let duplicate = |taken: bool| -> Result<()> {
                if taken {
                    Err(Error::parse(
                        source,
                        line,
                        format!("`{text}`: the same word appears twice in the block"),
                    ))
                } else {
                    Ok(())
                }
            };
            match address {
                Address::Axis(i) => {
                    duplicate(block.axes[i].is_some())?;
                    block.axes[i] = Some(num);
                }
                Address::ArcCentre(i) => {
                    duplicate(block.centre[i].is_some())?;
                    block.centre[i] = Some(num);
                }
                Address::ToolVector(i) => {
                    duplicate(block.vector[i].is_some())?;
                    block.vector[i] = Some(num.value);
                }
                Address::Radius => {
                    duplicate(block.radius.is_some())?;
                    block.radius = Some(num);
                }
                Address::ArcTurns => {
                    duplicate(block.turns.is_some())?;
                    block.turns = Some(num.value);
                }
                Address::ArcExtraTurns => {
                    duplicate(block.extra_turns.is_some())?;
                    block.extra_turns = Some(num.value);
                }
                Address::Feed => {
                    duplicate(block.feed.is_some())?;
                    block.feed = Some(num.value);
                }
                Address::G | Address::M => {
                    let table = if address == Address::G {
                        self.spec.g_codes
                    } else {
                        self.spec.m_codes
                    };
                    match lookup_code(table, num.value) {
                        Some(Action::Unsupported(message)) => {
                            return Err(self.error(line, format!("{text}: {message}")));
                        }
                        Some(action) => block.actions.push((text, action)),
                        None => self.warn(
                            line,
                            format!("unknown word `{text}` (not a {name} code): ignored"),
                        ),
                    }
                }
                Address::Ignored => {}
                Address::Unmodelled(message) => self.warn(line, format!("`{text}`: {message}")),
                Address::Unsupported(message) => {
                    return Err(self.error(line, format!("{text}: {message}")));
                }
            }
        }
        Ok(block)
    }

    /// Scale of a length word (mm per written unit), honouring integer increments.
    fn length(&self, num: Num) -> f64 {
        let scale = match (self.spec.integer_increments, num.point) {
            (Some(inc), false) => match self.units {
                Units::Mm => inc.mm,
                Units::Inch => inc.inch * MM_PER_INCH,
            },
            _ => self.units.mm_per_unit(),
        };
        num.value * scale
    }

    fn angle(&self, num: Num) -> f64 {
        match (self.spec.integer_increments, num.point) {
            (Some(inc), false) => num.value * inc.deg,
            _ => num.value,
        }
    }

    /// Interprets one block.
    pub(super) fn block(&mut self, line: usize, items: Vec<Item>) -> Result<()> {
        let block = self.collect(line, items)?;

        // Modal settings first (feed mode, F, units, plane, distance, TCP), then the motion.
        let mut motion_code: Option<(&str, Motion)> = None;
        let mut machine = false;
        let mut no_motion: Option<&str> = None;
        let mut end = false;
        for (text, action) in &block.actions {
            match *action {
                Action::FeedMode(mode) => {
                    if (self.spec.g94_clears_feed && mode == FeedMode::PerMinute)
                        || (self.feed_mode == FeedMode::InverseTime && mode != self.feed_mode)
                    {
                        self.feed = None;
                    }
                    self.feed_mode = mode;
                }
                Action::Motion(m) => {
                    if let Some((other, _)) = motion_code {
                        return Err(self.error(
                            line,
                            format!("two motion codes in one block: {other} and {text}"),
                        ));
                    }
                    motion_code = Some((text.as_str(), m));
                }
                Action::MotionCancel => self.motion = None,
                Action::Plane(p) => self.plane = p,
                Action::Units { units, feed } => {
                    self.units = units;
                    if feed {
                        self.feed_units = units;
                    }
                }
                Action::Distance(d) => self.distance = d,
                Action::ArcDistance(d) => self.arc_distance = d,
                Action::Tcp(t) => {
                    if t != self.tcp {
                        self.non_tcp_warned = false;
                    }
                    self.tcp = t;
                }
                Action::MachineCoordinates => machine = true,
                Action::NoMotion(message) => {
                    no_motion = Some(message);
                    self.warn(line, format!("{text}: {message}"));
                }
                Action::ProgramEnd => end = true,
                Action::Ignored => {}
                Action::Note(message) => self.warn(line, format!("{text}: {message}")),
                Action::Unsupported(message) => {
                    return Err(self.error(line, format!("{text}: {message}")));
                }
            }
        }
        if let Some(f) = block.feed {
            if f < 0.0 {
                return Err(self.error(line, format!("F{f}: a feed cannot be negative")));
            }
            if self.feed_mode == FeedMode::PerMinute {
                self.feed = (f > 0.0).then(|| ModalFeed {
                    mm_per_min: f * self.feed_units.mm_per_unit(),
                    raw: f,
                });
            }
        }
        if let Some((_, m)) = motion_code {
            self.motion = Some(m);
        }

        let has_axes = block.axes.iter().any(Option::is_some);
        let has_vector = block.vector.iter().any(Option::is_some);
        let has_centre = block.centre.iter().any(Option::is_some);
        let is_arc = matches!(self.motion, Some(Motion::ArcCw | Motion::ArcCcw));
        let ijk_vector = self.tcp == Tcp::OnIjkVector && !is_arc;
        let moves = no_motion.is_none()
            && (has_axes || has_vector || (has_centre && (ijk_vector || is_arc)));
        if moves {
            self.motion_block(line, &block, machine)?;
        } else if no_motion.is_none() && (has_centre || block.radius.is_some()) {
            self.warn(line, "I/J/K or R without a move: ignored");
        }
        if end {
            self.ended = true;
        }
        Ok(())
    }

    /// A motion block: resolves the target and emits its point(s).
    fn motion_block(&mut self, line: usize, block: &Block, machine: bool) -> Result<()> {
        let Some(motion) = self.motion else {
            return Err(self.error(
                line,
                "axis words without a motion mode: program G0, G1, G2 or G3 first",
            ));
        };
        let is_arc = matches!(motion, Motion::ArcCw | Motion::ArcCcw);
        if machine {
            if is_arc {
                return Err(self.error(line, "G53 (machine coordinates) with an arc"));
            }
            self.warn(
                line,
                "G53: machine-coordinate move taken as program coordinates",
            );
        }

        let start = self.pos;
        let mut end = start;
        for (i, word) in block.axes.iter().enumerate() {
            let Some(num) = *word else { continue };
            let value = if i < 3 {
                self.length(num)
            } else {
                self.angle(num)
            };
            if !value.is_finite() {
                return Err(self.error(line, format!("{}: value out of range", AXIS_NAMES[i])));
            }
            let incremental = self.distance == Distance::Incremental && !machine;
            end[i] = if incremental { start[i] + value } else { value };
            if i < 3 && !incremental {
                self.known[i] = true;
            }
            if i >= 3 {
                self.saw_rotary = true;
            }
        }
        let unknown: Vec<String> = (0..3)
            .filter(|&i| !self.known[i] && !self.unknown_warned[i])
            .map(|i| AXIS_NAMES[i].to_string())
            .collect();
        if !unknown.is_empty() {
            for i in 0..3 {
                if !self.known[i] {
                    self.unknown_warned[i] = true;
                }
            }
            self.warn(
                line,
                format!(
                    "{} not programmed yet: taken as 0 (the start position is unknown)",
                    unknown.join(", ")
                ),
            );
        }

        // Tool vector: Sinumerik-style words, or I J K on G0/G1 under Fanuc G43.5.
        let vector_words: [Option<f64>; 3] = if self.tcp == Tcp::OnIjkVector && !is_arc {
            std::array::from_fn(|i| block.centre[i].map(|n| n.value))
        } else {
            block.vector
        };
        if vector_words.iter().any(Option::is_some) {
            let v = Vector3::new(
                vector_words[0].unwrap_or(0.0),
                vector_words[1].unwrap_or(0.0),
                vector_words[2].unwrap_or(0.0),
            );
            let largest = v.amax();
            let scaled_norm = if largest > 0.0 {
                (v / largest).norm()
            } else {
                0.0
            };
            if largest * scaled_norm < MIN_TOOL_VECTOR_NORM {
                return Err(self.error(
                    line,
                    format!("tool vector ({}, {}, {}) has no direction", v.x, v.y, v.z),
                ));
            }
            self.vector = v / largest / scaled_norm;
        } else if !is_arc {
            let stray: Vec<&str> = ["I", "J", "K"]
                .iter()
                .zip(&block.centre)
                .filter(|(_, c)| c.is_some())
                .map(|(n, _)| *n)
                .collect();
            if !stray.is_empty() || block.radius.is_some() {
                let mut words = stray.join(" ");
                if block.radius.is_some() {
                    if !words.is_empty() {
                        words.push(' ');
                    }
                    words.push('R');
                }
                self.warn(line, format!("{words} on a straight move: ignored"));
            }
        }

        if self.tcp == Tcp::Off
            && !self.non_tcp_warned
            && (end[3..] != [0.0; 3]
                || block.axes[3..].iter().any(Option::is_some)
                || vector_words.iter().any(Option::is_some))
        {
            self.non_tcp_warned = true;
            self.warn(
                line,
                "motion with rotary axes or a tool vector outside tool-tip (TCP) mode: X Y Z \
                 taken as the tool tip",
            );
        }

        if is_arc {
            self.arc(line, motion, block, start, end)?;
        } else {
            let feed = self.linear_feed(line, motion, block, &start, &end)?;
            self.push(line, &end, feed);
        }
        self.pos = end;
        Ok(())
    }

    fn push(&mut self, line: usize, q: &[f64; 6], feed: Feed) {
        self.points.push(ClPoint {
            p: Vector3::new(q[0], q[1], q[2]),
            o: self.vector,
            feed,
            rotary: Some([q[3], q[4], q[5]]),
            line,
        });
    }

    /// The F of a G93 feed block, seconds for the whole block.
    fn inverse_time(&self, line: usize, block: &Block) -> Result<f64> {
        match block.feed {
            None => Err(self.error(
                line,
                "G93 (inverse time): F is required on every G1/G2/G3 block",
            )),
            Some(f) if f <= 0.0 => Err(self.error(
                line,
                format!("G93 (inverse time): F must be positive, found {f}"),
            )),
            Some(f) => Ok(60.0 / f),
        }
    }

    fn linear_feed(
        &self,
        line: usize,
        motion: Motion,
        block: &Block,
        start: &[f64; 6],
        end: &[f64; 6],
    ) -> Result<Feed> {
        if motion == Motion::Rapid {
            return Ok(Feed::Rapid);
        }
        if self.feed_mode == FeedMode::InverseTime {
            return Ok(Feed::BlockTime(self.inverse_time(line, block)?));
        }
        let Some(feed) = self.feed else {
            return Ok(Feed::Unspecified);
        };
        let moves_xyz = (0..3).any(|i| (end[i] - start[i]).abs() > XYZ_MOVE_THRESHOLD_MM);
        let rotary = (3..6)
            .map(|i| (end[i] - start[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        Ok(if !moves_xyz && rotary > 0.0 {
            Feed::BlockTime(rotary / (feed.raw / 60.0))
        } else {
            Feed::Programmed(feed.mm_per_min / 60.0)
        })
    }

    /// G2/G3: linearises the arc into chords.
    fn arc(
        &mut self,
        line: usize,
        motion: Motion,
        block: &Block,
        start: [f64; 6],
        end: [f64; 6],
    ) -> Result<()> {
        let (a, b, n) = self.plane.axes();
        let plane = self.plane.code();
        let centre_names = ['I', 'J', 'K'];
        if block.centre[n].is_some() {
            self.warn(
                line,
                format!(
                    "{} is not a centre word of a {plane} arc: ignored",
                    centre_names[n]
                ),
            );
        }
        let ccw = motion == Motion::ArcCcw;
        let (s0, s1) = (start[a], start[b]);
        let (e0, e1) = (end[a], end[b]);
        let chord = (e0 - s0).hypot(e1 - s1);
        let in_plane = block.centre[a].is_some() || block.centre[b].is_some();

        let (c0, c1) = if let Some(r) = block.radius {
            if in_plane {
                return Err(self.error(line, "an arc with both R and I/J/K"));
            }
            let r = self.length(r);
            if chord < FULL_CIRCLE_MM {
                return Err(self.error(
                    line,
                    "an R arc needs an end point different from its start (use I/J/K for a \
                     full circle)",
                ));
            }
            if r == 0.0 {
                return Err(self.error(line, "arc radius R is 0"));
            }
            let half = chord / 2.0;
            if half > r.abs() + R_ARC_TOLERANCE_MM {
                return Err(self.error(
                    line,
                    format!(
                        "arc radius {:.4} mm is smaller than half the distance to the end point \
                         ({half:.4} mm)",
                        r.abs()
                    ),
                ));
            }
            let h = (r * r - half * half).max(0.0).sqrt();
            let (m0, m1) = ((s0 + e0) / 2.0, (s1 + e1) / 2.0);
            // Left of the chord direction: counter-clockwise short arcs, clockwise long ones.
            let (l0, l1) = (-(e1 - s1) / chord, (e0 - s0) / chord);
            let side = if ccw == (r > 0.0) { 1.0 } else { -1.0 };
            (m0 + side * h * l0, m1 + side * h * l1)
        } else {
            if !in_plane {
                return Err(self.error(
                    line,
                    format!(
                        "{} arc needs its centre ({}, {}) or a radius R",
                        plane, centre_names[a], centre_names[b]
                    ),
                ));
            }
            let word = |i: usize| block.centre[i].map_or(0.0, |num| self.length(num));
            match self.arc_distance {
                Distance::Incremental => (s0 + word(a), s1 + word(b)),
                Distance::Absolute => (word(a), word(b)),
            }
        };

        let r_start = (s0 - c0).hypot(s1 - c1);
        let r_end = (e0 - c0).hypot(e1 - c1);
        let mismatch = (r_end - r_start).abs();
        if mismatch > ARC_RADIUS_MISMATCH_MM
            && mismatch > ARC_RADIUS_MISMATCH_RELATIVE * r_start.max(r_end)
        {
            return Err(self.error(
                line,
                format!(
                    "arc end point is not on the circle: radius {r_end:.4} mm at the end, \
                     {r_start:.4} mm at the start"
                ),
            ));
        }
        if r_start == 0.0 || r_end == 0.0 {
            return Err(self.error(line, "arc centre coincides with its start or end point"));
        }

        let theta_s = (s1 - c1).atan2(s0 - c0);
        let theta_e = (e1 - c1).atan2(e0 - c0);
        let tau = std::f64::consts::TAU;
        let mut sweep = if chord < FULL_CIRCLE_MM {
            tau
        } else if ccw {
            (theta_e - theta_s).rem_euclid(tau)
        } else {
            (theta_s - theta_e).rem_euclid(tau)
        };
        let extra = match (block.turns, block.extra_turns) {
            (Some(p), _) => {
                if p < 1.0 || p.fract() != 0.0 {
                    return Err(self.error(
                        line,
                        format!("arc turns P must be a whole number ≥ 1, found {p}"),
                    ));
                }
                p - 1.0
            }
            (None, Some(t)) => {
                if t < 0.0 || t.fract() != 0.0 {
                    return Err(
                        self.error(line, format!("TURN must be a whole number ≥ 0, found {t}"))
                    );
                }
                t
            }
            (None, None) => 0.0,
        };
        sweep += extra * tau;
        if !ccw {
            sweep = -sweep;
        }

        let r_max = r_start.max(r_end);
        let step = 2.0 * (1.0 - MAX_CHORD_ERROR_MM / r_max).max(-1.0).acos();
        let chords = ((sweep.abs() / step).ceil() as usize).max(1);
        let mut qs = Vec::with_capacity(chords);
        for k in 1..=chords {
            if k == chords {
                qs.push(end);
                break;
            }
            let t = k as f64 / chords as f64;
            let phi = theta_s + t * sweep;
            let r = r_start + t * (r_end - r_start);
            let mut q = [0.0; 6];
            for i in 0..6 {
                q[i] = start[i] + t * (end[i] - start[i]);
            }
            q[a] = c0 + r * phi.cos();
            q[b] = c1 + r * phi.sin();
            qs.push(q);
        }

        match self.feed_mode {
            FeedMode::InverseTime => {
                let total = self.inverse_time(line, block)?;
                let mut lengths = Vec::with_capacity(qs.len());
                let mut prev = start;
                for q in &qs {
                    lengths.push(
                        ((q[0] - prev[0]).powi(2)
                            + (q[1] - prev[1]).powi(2)
                            + (q[2] - prev[2]).powi(2))
                        .sqrt(),
                    );
                    prev = *q;
                }
                let sum: f64 = lengths.iter().sum();
                for (q, len) in qs.iter().zip(&lengths) {
                    let share = if sum > 0.0 {
                        len / sum
                    } else {
                        1.0 / qs.len() as f64
                    };
                    self.push(line, q, Feed::BlockTime(total * share));
                }
            }
            FeedMode::PerMinute => {
                let feed = match self.feed {
                    Some(f) => Feed::Programmed(f.mm_per_min / 60.0),
                    None => Feed::Unspecified,
                };
                for q in &qs {
                    self.push(line, q, feed);
                }
            }
        }
        Ok(())
    }
}
