//! The Klartext part of the interpreter: what Heidenhain's path functions, statements, frames
//! and cycles do, on the same modal state, motion, arc and cycle code as the G-code dialects.
//! The words and what they do are described in [`crate::toolpath::gcode::klartext`].

use nalgebra::{Matrix3, Vector3};

use super::super::cycles;
use super::super::dialect::{PathKind, Statement};
use super::super::klartext;
use super::super::lexer::Num;
use super::*;
use crate::base::angle_between;

/// The Klartext words of a block the interpreter acts on after the modal settings.
#[derive(Debug, Default)]
pub(in crate::toolpath::gcode) struct KlartextWords {
    /// The path function (`C`, `CC`, `CR`, `CT`, `CP`, `LP`), as written.
    pub(in crate::toolpath::gcode) path: Option<(String, PathKind)>,
    /// A statement, as written, and its arguments.
    pub(in crate::toolpath::gcode) statement: Option<(String, Statement, String)>,
    /// `FMAX`.
    pub(in crate::toolpath::gcode) rapid: bool,
    /// `FAUTO`.
    pub(in crate::toolpath::gcode) tool_feed: bool,
    /// `M99` (true) / `M89` (false).
    pub(in crate::toolpath::gcode) cycle_call: Option<bool>,
    /// `M140`, and `MB MAX`.
    pub(in crate::toolpath::gcode) retract: bool,
    pub(in crate::toolpath::gcode) retract_max: bool,
}

/// What a Klartext program has set up.
#[derive(Debug, Default)]
pub(super) struct State {
    /// `CC`: the arc plane and the centre's coordinates in its two axes (program
    /// coordinates, mm).
    pole: Option<(Plane, [f64; 2])>,
    /// `TOOL CALL … F` (mm/min) and `S` (rpm).
    tool_feed: Option<f64>,
    spindle_rpm: Option<f64>,
    /// The cycle `CYCL DEF` defined and its line.
    cycle: Option<(u32, usize)>,
    /// The Q parameters (numbers) that `CYCL DEF` gave: a parameter that newer software added
    /// to a cycle is read from its own definition only, not from an earlier cycle's.
    cycle_params: Vec<u32>,
    /// `M89` in force.
    modal_call: bool,
    /// `PATTERN DEF` points: X, Y (program coordinates, mm) and Z (added to Q203).
    pattern: Vec<[f64; 3]>,
    /// `CYCL DEF 7`: the datum shift, untilted workpiece coordinates, mm.
    datum_shift: Vector3<f64>,
    /// `PLANE`: the working plane's rotation.
    plane: Option<Matrix3<f64>>,
    /// After `PLANE … STAY`: the tool's orientation (workpiece coordinates) until a block
    /// positions a rotary axis.
    pub(super) stay_orientation: Option<Vector3<f64>>,
    /// `PLANE … SEQ±` with two solutions for the rotary axes: the positions the control
    /// computed for the one SEQ asks for (axis positions `[A, B, C]`, degrees; `None` for an
    /// axis the kinematics does not turn), until a block positions the axes there (`L A+Q120
    /// C+Q122` after STAY).
    pub(super) sequence: Option<[Option<f64>; 3]>,
    /// The next point is where the rotary axes were positioned to such a solution: it carries
    /// them as programmed positions (elsewhere under a tilted plane the tool vector rules and
    /// the kinematics chooses).
    pub(super) sequence_point: bool,
    /// The line of the active `PLANE` (its tool axis is the one rotary words must keep).
    plane_line: usize,
    /// The block being pushed programs rotary words under a `PLANE` (`L A-90 C+270` after
    /// `STAY`): its points carry them as programmed positions, as the control moves the axes
    /// where the block says; elsewhere under a plane the tool vector rules.
    pub(super) programmed_rotary: bool,
    /// The line of a `PLANE … TURN`/`MOVE` or an `L A+Q120 C+Q122` without SEQ that moved the
    /// rotary axes to a solution the reader leaves to the kinematics: until a block programs
    /// every rotary axis again, the reader does not know where they stand.
    pub(super) rotary_unknown: Option<usize>,
    /// Rotary words under a plane were read without the machine's kinematics (said once).
    unchecked_warned: bool,
    /// The preset `CYCL DEF 247` activated first (`Some(None)`: one whose Q339 is unknown).
    preset: Option<Option<f64>>,
    /// The line of a `CYCL DEF 7` that left a non-zero shift programmed while a plane was
    /// active (its meaning then is the control's; an error if anything else follows).
    tilted_shift: Option<usize>,
}

impl Interpreter<'_> {
    /// The Klartext part of a block, after its modal settings (F, M functions, TCP).
    pub(super) fn klartext_block(
        &mut self,
        line: usize,
        mut block: Block,
        k: KlartextWords,
        machine: bool,
    ) -> Result<()> {
        if let Some(at) = self.klartext.tilted_shift
            && !matches!(k.statement, Some((_, Statement::CycleDef, _)))
        {
            return Err(self.error(
                line,
                format!(
                    "the datum shift of line {at} was programmed while a PLANE was active: \
                     feedopt reads datum shifts in the untilted system (a shift reset to 0 \
                     there is fine); program the shift before PLANE"
                ),
            ));
        }
        if k.tool_feed {
            let Some(f) = self.klartext.tool_feed else {
                return Err(self.error(line, "FAUTO: the TOOL CALL gave no F; program F in mm/min"));
            };
            self.feed = Some(ModalFeed {
                mm_per_min: f,
                raw: f,
            });
        }
        if let Some((text, statement, args)) = k.statement {
            return self.statement(line, &text, statement, &args);
        }
        if !k.retract && (k.retract_max || block.retract.is_some()) {
            return Err(self.error(line, "MB (the retract of M140) without M140"));
        }
        if k.retract {
            if block.axes.iter().any(Option::is_some) || k.path.is_some() {
                return Err(self.error(
                    line,
                    "M140 with a move in the same block: put the move in a block of its own",
                ));
            }
            let mb = if k.retract_max {
                None
            } else {
                Some(block.retract.ok_or_else(|| {
                    self.error(line, "M140 without MB: give MB <distance in mm> or MB MAX")
                })?)
            };
            self.retract(line, "M140", mb, block.feed.is_some())?;
        }
        let arc = matches!(
            k.path,
            Some((
                _,
                PathKind::PoleArc | PathKind::RadiusArc | PathKind::TangentArc | PathKind::PolarArc
            ))
        );
        if k.rapid && arc {
            return Err(self.error(line, "FMAX on a circular path: program the arc's feed F"));
        }
        if k.rapid && self.motion == Some(Motion::Linear) {
            self.motion = Some(Motion::Rapid);
        }
        let positions = block.axes[..2].iter().any(Option::is_some);
        match k.path {
            Some((text, PathKind::Centre)) => self.circle_centre(line, &text, &block, machine)?,
            Some((text, kind)) => {
                if machine {
                    return Err(self.error(line, format!("{text} with M91: not supported")));
                }
                self.klartext_path(line, &text, kind, &mut block, k.rapid)?;
                self.motion_block(line, &block, false)?;
            }
            None => {
                let moves = block.axes.iter().any(Option::is_some)
                    || block.plane_rotary.iter().any(|&q| q)
                    || block.vector.iter().any(Option::is_some);
                if moves {
                    self.motion_block(line, &block, machine)?;
                }
            }
        }
        match k.cycle_call {
            Some(true) => {
                self.klartext.modal_call = false;
                self.run_cycle(line, 0.0)?;
            }
            Some(false) => {
                self.klartext.modal_call = true;
                if positions {
                    self.run_cycle(line, 0.0)?;
                }
            }
            None if self.klartext.modal_call && positions => self.run_cycle(line, 0.0)?,
            None => {}
        }
        Ok(())
    }

    fn statement(&mut self, line: usize, text: &str, st: Statement, args: &str) -> Result<()> {
        match st {
            Statement::ProgramBegin => self.program_begin(line, args),
            Statement::ToolCall => self.tool_call(line, args),
            Statement::CycleDef => self.cycle_def(line, args),
            Statement::CycleCall => self.cycle_call(line, args),
            Statement::PatternDef => self.pattern_def(line, args),
            Statement::Plane => self.plane(line, args),
            Statement::Tcpm => self.tcpm(line, args),
            // Read by the lexer.
            Statement::Fn => Ok(()),
            Statement::Corner(chamfer) => self.klartext_corner(line, text, chamfer, args),
        }
    }

    /// `RND R5 [F…]` / `CHF 2 [F…]` right after a straight feed move (`L`): the corner to the
    /// next move rounded with radius R, or chamfered from the chamfer side length before the
    /// corner to as far after it (TNC 640 Klartext manual, "Path contours — Cartesian
    /// coordinates": RND, CHF); an F is the corner's own feed (mm/min). Made by the next move
    /// as G-code's `,R`/`,C` are ([`Interpreter::corner_to`]): what that cannot make is an
    /// error naming the block.
    fn klartext_corner(
        &mut self,
        line: usize,
        text: &str,
        chamfer: bool,
        args: &str,
    ) -> Result<()> {
        let written = format!("{text} {}", args.trim());
        let (mut size, mut feed) = (None, None);
        for w in klartext::words(args) {
            let upper = w.to_ascii_uppercase();
            if let Some(v) = upper.strip_prefix('F') {
                if v.is_empty() || v == "MAX" || v == "AUTO" || v == "U" || v == "Z" {
                    return Err(self.error(
                        line,
                        format!(
                            "`{written}`: `{w}` on a rounding or chamfer is not read: give its \
                             feed as a number, or none (the contour's feed)"
                        ),
                    ));
                }
                feed = Some(self.klartext_value(line, &w, v)?);
            } else if !chamfer && let Some(v) = upper.strip_prefix('R') {
                size = Some(self.klartext_value(line, &w, v)?);
            } else if chamfer && size.is_none() {
                size = Some(self.klartext_value(line, &w, &w)?);
            } else {
                return Err(self.error(line, format!("`{written}`: unexpected `{w}`")));
            }
        }
        let Some(size) = size.filter(|s| *s > 0.0) else {
            return Err(self.error(
                line,
                format!(
                    "`{written}`: {} larger than 0 is needed",
                    if chamfer {
                        "a chamfer side length"
                    } else {
                        "a rounding radius R"
                    }
                ),
            ));
        };
        if feed.is_some_and(|f| f <= 0.0) {
            return Err(self.error(line, format!("`{written}`: the feed must be above 0")));
        }
        let after_straight = self.corner.is_none()
            && self.straight_end == Some((self.points.len(), self.event_counts()));
        if !after_straight {
            return Err(self.error(
                line,
                format!(
                    "`{written}`: a rounding or chamfer is modelled right after a straight feed \
                     move (L) only, not after an arc, a rapid (FMAX), a dwell or another RND/CHF: \
                     post the corner as a move of its own"
                ),
            ));
        }
        self.corner = Some(PendingCorner {
            line,
            text: written,
            word: if chamfer {
                CornerWord::ChamferLeg
            } else {
                CornerWord::Round
            },
            size,
            at: self.points.len() - 1,
            counts: self.event_counts(),
            feed: feed.map(|f| f / 60.0),
        });
        Ok(())
    }

    /// A value of a statement's word.
    fn klartext_value(&self, line: usize, word: &str, text: &str) -> Result<f64> {
        klartext::value(text, &self.vars).map_err(|e| self.error(line, format!("`{word}`: {e}")))
    }

    fn program_begin(&mut self, line: usize, args: &str) -> Result<()> {
        let words = klartext::words(args);
        match words.last().map(|w| w.to_ascii_uppercase()).as_deref() {
            Some("MM") => {
                self.units = Units::Mm;
                self.feed_units = Units::Mm;
                Ok(())
            }
            // (NX's Heidenhain posts write `IN` for inch.)
            Some(unit @ ("INCH" | "IN")) => Err(self.error(
                line,
                format!(
                    "BEGIN PGM … {unit}: inch Klartext programs are not supported; post the \
                     program in MM"
                ),
            )),
            _ => Err(self.error(line, "BEGIN PGM without its unit: end the block with MM")),
        }
    }

    fn tool_call(&mut self, line: usize, args: &str) -> Result<()> {
        for (k, word) in klartext::words(args).into_iter().enumerate() {
            let upper = word.to_ascii_uppercase();
            // The tool: `TOOL CALL 5 Z …` by number, `TOOL CALL "MILL_D10" Z …` by name (a
            // TOOL CALL without either changes the spindle speed or feed only).
            if k == 0 {
                if word.len() >= 2 && word.starts_with('"') && word.ends_with('"') {
                    let name = word[1..word.len() - 1].to_string();
                    self.change_tool(line, ToolSelect::Name(name));
                    continue;
                }
                if word.starts_with(|c: char| c.is_ascii_digit()) {
                    let n = word
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.fract() == 0.0 && *v <= u32::MAX as f64)
                        .ok_or_else(|| {
                            self.error(
                                line,
                                format!("TOOL CALL {word}: a tool number is a whole number"),
                            )
                        })?;
                    self.change_tool(line, ToolSelect::Number(n as u32));
                    continue;
                }
            }
            match upper.as_str() {
                "Z" => self.plane = Plane::Xy,
                "X" | "Y" => {
                    return Err(self.error(
                        line,
                        format!("TOOL CALL … {upper}: a tool axis other than Z is not supported"),
                    ));
                }
                _ => {
                    let value_start = |rest: &str| {
                        rest.starts_with(|c: char| {
                            c.is_ascii_digit() || matches!(c, '+' | '-' | '.' | 'Q')
                        })
                    };
                    if let Some(rest) = upper.strip_prefix('S')
                        && value_start(rest)
                    {
                        let rpm = self.klartext_value(line, &word, rest)?;
                        self.klartext.spindle_rpm = Some(rpm);
                        self.set_spindle(line, rpm);
                    } else if let Some(rest) = upper.strip_prefix('F')
                        && value_start(rest)
                    {
                        let f = self.klartext_value(line, &word, rest)?;
                        if f <= 0.0 {
                            return Err(self.error(
                                line,
                                format!("TOOL CALL `{word}`: a feed must be positive"),
                            ));
                        }
                        self.klartext.tool_feed = Some(f);
                    }
                }
            }
        }
        Ok(())
    }

    /// `CC`: the pole and the arc plane.
    fn circle_centre(
        &mut self,
        line: usize,
        text: &str,
        block: &Block,
        machine: bool,
    ) -> Result<()> {
        if machine {
            return Err(self.error(line, "CC with M91: not supported"));
        }
        if block.axes[3..].iter().any(Option::is_some) {
            return Err(self.error(
                line,
                "CC takes the centre's coordinates X, Y or Z, not a rotary axis",
            ));
        }
        let given: Vec<usize> = (0..3).filter(|&i| block.axes[i].is_some()).collect();
        let plane = match given.as_slice() {
            [] | [0] | [1] | [0, 1] => Plane::Xy,
            [1, 2] => Plane::Yz,
            [0, 2] => Plane::Zx,
            _ => {
                return Err(self.error(
                    line,
                    format!(
                        "{text} with {}: give the centre's two coordinates in one plane (X Y, \
                         Y Z or X Z)",
                        given
                            .iter()
                            .map(|&i| AXIS_NAMES[i].to_string())
                            .collect::<Vec<_>>()
                            .join(" ")
                    ),
                ));
            }
        };
        let (a, b, _) = plane.axes();
        let mut c = [0.0; 2];
        for (k, i) in [a, b].into_iter().enumerate() {
            c[k] = match block.axes[i] {
                Some(num) => {
                    let v = self.length(num);
                    if !v.is_finite() || v.abs() > MAX_COORDINATE_MM {
                        return Err(self.error(
                            line,
                            format!(
                                "{text}: {} is beyond ±{MAX_COORDINATE_MM:e} mm",
                                AXIS_NAMES[i]
                            ),
                        ));
                    }
                    if block.incremental[i] {
                        self.pos[i] + v
                    } else {
                        v
                    }
                }
                None => {
                    self.warn_unknown(line);
                    self.pos[i]
                }
            };
        }
        self.klartext.pole = Some((plane, c));
        Ok(())
    }

    fn pole(&self, line: usize, text: &str) -> Result<(Plane, [f64; 2])> {
        self.klartext.pole.ok_or_else(|| {
            self.error(
                line,
                format!("{text} needs a circle centre: program CC before it"),
            )
        })
    }

    /// Sets up an arc or polar line: its plane, centre, sweep and end words.
    fn klartext_path(
        &mut self,
        line: usize,
        text: &str,
        kind: PathKind,
        block: &mut Block,
        rapid: bool,
    ) -> Result<()> {
        let direction = |block: &Block| -> Result<Motion> {
            match block.direction {
                Some(d) if d > 0.0 => Ok(Motion::ArcCcw),
                Some(_) => Ok(Motion::ArcCw),
                None => Err(self.error(
                    line,
                    format!("{text} without DR+ or DR-: give the direction of rotation"),
                )),
            }
        };
        let polar = |block: &Block| block.polar_angle.is_some() || block.polar_radius.is_some();
        match kind {
            PathKind::PoleArc => {
                let (plane, c) = self.pole(line, text)?;
                if !block.axes.iter().any(Option::is_some) {
                    return Err(self.error(line, format!("{text} without an end point")));
                }
                if polar(block) {
                    return Err(self.error(line, format!("{text} with PA/PR: program CP or LP")));
                }
                self.motion = Some(direction(block)?);
                block.arc_plane = Some(plane);
                block.arc_centre = Some(ArcCentre::At(c));
            }
            PathKind::RadiusArc => {
                if block.radius.is_none() {
                    return Err(self.error(line, format!("{text} without R (the radius)")));
                }
                self.motion = Some(direction(block)?);
                block.arc_plane = Some(Plane::Xy);
            }
            PathKind::TangentArc => {
                let t = match self.tangent {
                    Some((Plane::Xy, t, n)) if n == self.points.len() => t,
                    _ => {
                        return Err(self.error(
                            line,
                            format!(
                                "{text} continues the contour tangentially, so it needs a line \
                                 or arc in the XY plane right before it"
                            ),
                        ));
                    }
                };
                if block.direction.is_some() || block.radius.is_some() {
                    return Err(
                        self.error(line, format!("{text} takes only the end point: no DR or R"))
                    );
                }
                self.motion = Some(Motion::ArcCcw);
                block.arc_plane = Some(Plane::Xy);
                block.arc_centre = Some(ArcCentre::Tangent(t));
            }
            PathKind::PolarArc | PathKind::PolarLine => {
                let (plane, c) = self.pole(line, text)?;
                let (a, b, _) = plane.axes();
                for i in [a, b] {
                    if block.axes[i].is_some() {
                        return Err(self.error(
                            line,
                            format!(
                                "{text} with {}: the end point is given by polar coordinates \
                                 about CC",
                                AXIS_NAMES[i]
                            ),
                        ));
                    }
                }
                let (d0, d1) = (self.pos[a] - c[0], self.pos[b] - c[1]);
                let r0 = d0.hypot(d1);
                let theta0 = d1.atan2(d0).to_degrees();
                let (r, theta, sweep) = if kind == PathKind::PolarArc {
                    if block.polar_radius.is_some() {
                        return Err(self.error(
                            line,
                            format!("{text} takes no PR: the radius is the distance to CC"),
                        ));
                    }
                    if r0 < 1e-9 {
                        return Err(self.error(
                            line,
                            format!("{text} starts at its centre CC: the radius is 0"),
                        ));
                    }
                    let Some((angle, incremental)) = block.polar_angle else {
                        return Err(self.error(line, format!("{text} without PA or IPA")));
                    };
                    let sweep = if incremental {
                        if block.direction.is_some_and(|d| d * angle < 0.0) {
                            return Err(self.error(
                                line,
                                format!(
                                    "{text}: IPA{angle:+} turns against the direction DR given"
                                ),
                            ));
                        }
                        angle
                    } else {
                        let ccw = direction(block)? == Motion::ArcCcw;
                        let delta = if ccw {
                            (angle - theta0).rem_euclid(360.0)
                        } else {
                            -(theta0 - angle).rem_euclid(360.0)
                        };
                        if delta.abs() < 1e-9 {
                            if ccw { 360.0 } else { -360.0 }
                        } else {
                            delta
                        }
                    };
                    if sweep == 0.0 {
                        return Err(self.error(line, format!("{text} with a sweep of 0°")));
                    }
                    (r0, theta0 + sweep, Some(sweep))
                } else {
                    let r = match block.polar_radius {
                        Some((v, false)) => v,
                        Some((v, true)) => r0 + v,
                        None => r0,
                    };
                    if r < 0.0 {
                        return Err(self.error(line, format!("{text}: a negative radius {r}")));
                    }
                    let theta = match block.polar_angle {
                        Some((v, false)) => v,
                        Some((v, true)) => theta0 + v,
                        None => theta0,
                    };
                    (r, theta, None)
                };
                let rad = theta.to_radians();
                block.axes[a] = Some(Num {
                    value: c[0] + r * rad.cos(),
                    point: true,
                });
                block.axes[b] = Some(Num {
                    value: c[1] + r * rad.sin(),
                    point: true,
                });
                block.incremental[a] = false;
                block.incremental[b] = false;
                match sweep {
                    Some(sweep) => {
                        self.motion = Some(if sweep > 0.0 {
                            Motion::ArcCcw
                        } else {
                            Motion::ArcCw
                        });
                        block.arc_plane = Some(plane);
                        block.arc_centre = Some(ArcCentre::At(c));
                        block.arc_sweep = Some(sweep.to_radians());
                    }
                    None => {
                        self.motion = Some(if rapid { Motion::Rapid } else { Motion::Linear });
                    }
                }
            }
            PathKind::Centre => {}
        }
        Ok(())
    }

    /// The tool axis in program coordinates.
    fn tool_axis(&self, line: usize, what: &str) -> Result<Vector3<f64>> {
        if let Some(pose) = self.axes_pose(&self.pos) {
            // Outside tool-tip mode, the axes read as positions: the program direction that
            // moves the tip along the tool axis the kinematics gives.
            let a = self.program_at(pose.p, &self.pos);
            let b = self.program_at(pose.p + pose.k, &self.pos);
            return Ok((b - a).normalize());
        }
        if let Some(o) = self.klartext.stay_orientation {
            return Ok(self.frame_now().r.transpose() * o);
        }
        if self.tcp != Tcp::Off && self.pos[3..].iter().any(|a| *a != 0.0) {
            return Err(self.error(
                line,
                format!(
                    "{what} with the tool tilted by rotary axes under TCP: feedopt cannot tell \
                     the tool axis (that is the machine's kinematics); retract with L"
                ),
            ));
        }
        Ok(self.vector)
    }

    /// Retracts along the tool axis by `mb` mm, or to the Z travel limit (`None`).
    fn retract(&mut self, line: usize, what: &str, mb: Option<f64>, at_feed: bool) -> Result<()> {
        let axis = self.tool_axis(line, what)?;
        let start = self.pos;
        let mut end = start;
        match mb {
            Some(d) => {
                if !d.is_finite() || d.abs() > MAX_COORDINATE_MM {
                    return Err(self.error(line, format!("{what} MB {d}: out of range")));
                }
                for i in 0..3 {
                    end[i] += d * axis[i];
                }
            }
            None => {
                let up = self.frame_now().r * axis;
                if (up - Vector3::z()).norm() > 1e-9 {
                    return Err(self.error(
                        line,
                        format!(
                            "{what} MB MAX with a tilted tool: how far the tool can go is the \
                             machine's; give MB <distance in mm>"
                        ),
                    ));
                }
                let Some(machine) = self.machine else {
                    return Err(self.error(
                        line,
                        format!(
                            "{what} MB MAX retracts Z to its travel limit: read the program \
                             with a machine file (its axes.Z \"max\")"
                        ),
                    ));
                };
                let Some((_, z_max)) = machine.travel[2] else {
                    return Err(self.error(
                        line,
                        format!(
                            "{what} MB MAX retracts Z to its travel limit, which {} does not \
                             give: add \"min\" and \"max\" to axes.Z (machine coordinates, mm)",
                            machine.file.display()
                        ),
                    ));
                };
                let mut m = self.to_machine(Vector3::new(start[0], start[1], start[2]));
                m.z = z_max;
                let p = self.machine_to_program(m);
                end[..3].copy_from_slice(p.as_slice());
                self.known[2] = true;
            }
        }
        self.warn_unknown(line);
        if end != start {
            let feed = match (at_feed, self.feed) {
                (true, Some(f)) => Feed::Programmed(f.mm_per_min / 60.0),
                _ => Feed::Rapid,
            };
            self.push(line, &end, feed);
            self.pos = end;
        }
        self.tangent = None;
        Ok(())
    }

    /// Recomputes the frames from the datum shift and the plane; the tool does not move.
    fn set_klartext_frame(&mut self) {
        let p = self.tip_at(&self.pos);
        let t = self.klartext.datum_shift;
        match self.klartext.plane {
            Some(r) => {
                self.swivel = Some(Frame { r, t });
                self.programmable = Frame::IDENTITY;
            }
            None => {
                self.swivel = None;
                self.programmable = Frame::translation(t);
            }
        }
        let q = self.program_at(p, &self.pos);
        self.pos[..3].copy_from_slice(q.as_slice());
    }

    /// The tool's orientation now, workpiece coordinates.
    fn orientation(&self) -> Vector3<f64> {
        if let Some(pose) = self.axes_pose(&self.pos) {
            return pose.k;
        }
        self.klartext
            .stay_orientation
            .unwrap_or_else(|| self.frame_now().r * self.vector)
    }

    fn plane(&mut self, line: usize, args: &str) -> Result<()> {
        let words = klartext::named_words(args);
        let Some((kind, _)) = words.first().cloned() else {
            return Err(self.error(line, "PLANE without its kind (SPATIAL, RESET, …)"));
        };
        let mut mode: Option<String> = None;
        let mut mb: Option<Option<f64>> = None;
        let mut values: Vec<(String, f64)> = Vec::new();
        // (positive, SYM rather than SEQ)
        let mut sequence: Option<(bool, bool)> = None;
        let mut k = 1;
        while k < words.len() {
            let (name, text) = &words[k];
            match (name.as_str(), text.as_str()) {
                ("TURN" | "MOVE" | "STAY", "") => mode = Some(name.clone()),
                ("MB", "") => match words.get(k + 1) {
                    Some((n, t)) if n == "MAX" && t.is_empty() => {
                        mb = Some(None);
                        k += 1;
                    }
                    Some((n, t)) if n.is_empty() && !t.is_empty() => {
                        mb = Some(Some(self.klartext_value(line, "MB", t)?));
                        k += 1;
                    }
                    _ => {
                        return Err(self.error(line, "PLANE … MB without a distance or MAX"));
                    }
                },
                ("MBMAX", "") => mb = Some(None),
                ("MB", t) => mb = Some(Some(self.klartext_value(line, "MB", t)?)),
                // Which of the rotary axes' two solutions: the master axis's sign.
                ("SEQ", "+") => sequence = Some((true, false)),
                ("SEQ", "-") => sequence = Some((false, false)),
                // The same from the master axis's symmetry point (TNC7).
                ("SYM", "+") => sequence = Some((true, true)),
                ("SYM", "-") => sequence = Some((false, true)),
                ("SEQ" | "SYM", t) => {
                    return Err(self.error(
                        line,
                        format!("PLANE: `{name}{t}`: the solution is {name}+ or {name}-"),
                    ));
                }
                // The rotary axes' feed and the table's role: the machine's.
                ("FMAX" | "TABLE" | "COORD" | "ROT", _) | ("F" | "ABST" | "DIST", _) => {}
                (n, t)
                    if !t.is_empty()
                        && n.chars().all(|c| c.is_ascii_alphabetic())
                        && !n.is_empty() =>
                {
                    let v = self.klartext_value(line, &format!("{n}{t}"), t)?;
                    values.push((n.to_string(), v));
                }
                _ => {
                    return Err(self.error(line, format!("PLANE: unknown word `{name}{text}`")));
                }
            }
            k += 1;
        }
        let get = |name: &str| {
            values
                .iter()
                .find(|(n, _)| n == name)
                .map_or(0.0, |(_, v)| *v)
        };
        let allowed = |names: &[&str]| -> Result<()> {
            for (n, _) in &values {
                if !names.contains(&n.as_str()) {
                    return Err(self.error(line, format!("PLANE {kind}: unknown word `{n}`")));
                }
            }
            Ok(())
        };
        let rotation = match kind.as_str() {
            "SPATIAL" => {
                allowed(&["SPA", "SPB", "SPC"])?;
                Some(frames::rot_zyx([get("SPA"), get("SPB"), get("SPC")]))
            }
            "RELATIV" | "RELATIVE" => {
                allowed(&["SPA", "SPB", "SPC"])?;
                let r = frames::rot_zyx([get("SPA"), get("SPB"), get("SPC")]);
                Some(self.klartext.plane.unwrap_or_else(Matrix3::identity) * r)
            }
            "EULER" => {
                allowed(&["EULPR", "EULNU", "EULROT"])?;
                Some(frames::euler_zxz(get("EULPR"), get("EULNU"), get("EULROT")))
            }
            "VECTOR" => {
                allowed(&["BX", "BY", "BZ", "NX", "NY", "NZ"])?;
                let b = Vector3::new(get("BX"), get("BY"), get("BZ"));
                let n = Vector3::new(get("NX"), get("NY"), get("NZ"));
                let (Some(z), true) = (crate::toolpath::unit_tool_vector(n), b.norm() > 0.0) else {
                    return Err(self.error(
                        line,
                        "PLANE VECTOR: the base vector B and the normal N need a direction",
                    ));
                };
                let Some(x) = crate::toolpath::unit_tool_vector(b - z * z.dot(&b)) else {
                    return Err(self.error(
                        line,
                        "PLANE VECTOR: the base vector B is parallel to the normal N",
                    ));
                };
                Some(Matrix3::from_columns(&[x, z.cross(&x), z]))
            }
            "RESET" => {
                allowed(&[])?;
                None
            }
            "AXIAL" => {
                return Err(self.error(
                    line,
                    "PLANE AXIAL (the plane by rotary axis positions) depends on the machine's \
                     kinematics and is not supported: post the plane as PLANE SPATIAL, EULER \
                     or VECTOR",
                ));
            }
            other => {
                return Err(self.error(
                    line,
                    format!(
                        "PLANE {other} is not supported (SPATIAL, EULER, VECTOR, RELATIV and \
                         RESET are): post the plane as PLANE SPATIAL"
                    ),
                ));
            }
        };
        let Some(mode) = mode else {
            return Err(self.error(line, format!("PLANE {kind} without TURN, MOVE or STAY")));
        };
        if let Some(mb) = mb {
            if mode == "STAY" {
                return Err(self.error(line, "PLANE … STAY with MB: STAY moves nothing"));
            }
            self.retract(line, "PLANE … MB", mb, false)?;
        }
        let before = self.orientation();
        self.klartext.plane = rotation;
        self.klartext.plane_line = line;
        self.klartext.stay_orientation = None;
        self.set_klartext_frame();
        let after = self.frame_now().r * self.vector;
        self.klartext.sequence = None;
        self.klartext.sequence_point = false;
        if let Some((positive, symmetric)) = sequence {
            self.klartext.sequence = self.sequence_positions(line, positive, symmetric, &after)?;
        }
        if mode == "STAY" {
            if (after - before).norm() > 1e-12 {
                self.klartext.stay_orientation = Some(before);
            }
        } else {
            if rotation.is_none() {
                self.pos[3..].fill(0.0);
                self.klartext.rotary_unknown = None;
            } else if self.klartext.sequence.is_none() {
                // TURN, MOVE without SEQ: the kinematics chooses where the axes go.
                self.mark_rotary_unknown(line, &after);
            }
            // TURN, MOVE: the rotary axes go to the solution SEQ asked for now; the next point
            // (this turn's, where the tool turns) stands there.
            if let Some(p) = self.klartext.sequence.take() {
                self.klartext.rotary_unknown = None;
                let shift = self.offsets.shift();
                for (i, v) in p.iter().enumerate() {
                    if let Some(v) = v {
                        self.pos[3 + i] = v - shift[3 + i];
                    }
                }
                self.saw_rotary = true;
                self.klartext.sequence_point = true;
            }
            if !self.points.is_empty() && (after - before).norm() > 1e-12 {
                let q = self.pos;
                self.push(line, &q, Feed::Rapid);
            }
        }
        self.tangent = None;
        Ok(())
    }

    /// The tool axis (workpiece coordinates) the machine's kinematics gives at the rotary
    /// positions `q` (`[A, B, C]`, program degrees, before the work offsets' shift).
    fn tool_axis_at(
        kinematics: &crate::kinematics::Kinematics,
        q: [f64; 3],
        shift: &[f64; 6],
    ) -> Vector3<f64> {
        kinematics.tool_axis(kinematics.angles_from_rotary([
            q[0] + shift[3],
            q[1] + shift[4],
            q[2] + shift[5],
        ]))
    }

    /// The rotary axes went, at `line`, to a solution for the tool axis `k` (workpiece
    /// coordinates) that the kinematics chooses: unless the positions the reader holds already
    /// give `k` (the kinematics then keeps them), they are unknown from here on.
    fn mark_rotary_unknown(&mut self, line: usize, k: &Vector3<f64>) {
        let Some((kinematics, _)) = two_rotary_kinematics(self.machine) else {
            return;
        };
        let shift = self.offsets.shift();
        let q = [self.pos[3], self.pos[4], self.pos[5]];
        let at = Self::tool_axis_at(kinematics, q, &shift);
        if angle_between(&at, k) > ROTARY_AXIS_TOLERANCE_RAD {
            self.klartext.rotary_unknown = Some(line);
        }
    }

    /// A block whose words position rotary axes (`L A-90 C+270 R0 FMAX`, its end `end`): under
    /// a `PLANE` the control moves them where the block says, and the working plane stays the
    /// plane's. Returns whether the block's points carry those positions for that reason
    /// (false outside a Klartext plane: there they do or not as before, and Sinumerik's
    /// `CYCLE800` frame keeps its own rule). With the machine's kinematics, the positions
    /// must put the tool along the plane's tool axis (outside tool-tip mode: under `M128` the
    /// rotary axes orient the tool as they do without a plane) and may not leave an axis the
    /// reader does not know; an error naming the line otherwise. Without the kinematics that
    /// cannot be checked: a warning, once.
    pub(super) fn plane_rotary_words(
        &mut self,
        line: usize,
        block: &Block,
        end: &[f64; 6],
    ) -> Result<bool> {
        let words = block.axes[3..].iter().any(Option::is_some);
        if block.plane_rotary.iter().any(|&q| q) {
            if self.klartext.sequence_point {
                // `L A+Q120 C+Q122` to the positions computed for SEQ: known.
                self.klartext.rotary_unknown = None;
            } else {
                // Without SEQ the kinematics chooses.
                let k = self.frame_now().r * self.vector;
                self.mark_rotary_unknown(line, &k);
            }
        }
        let under_plane = self.klartext.plane.is_some();
        if !words {
            return Ok(false);
        }
        let Some((kinematics, turned)) = two_rotary_kinematics(self.machine) else {
            if under_plane
                && self.machine.is_none_or(|m| m.kinematics.is_none())
                && !self.klartext.unchecked_warned
            {
                self.klartext.unchecked_warned = true;
                self.warn(
                    line,
                    "rotary axis words under a PLANE: the axes go where the block says; whether \
                     that keeps the tool along the plane's tool axis depends on the machine's \
                     kinematics, which the reader was not given (read the program with a \
                     machine file to check it)",
                );
            }
            return Ok(under_plane);
        };
        let letters = ["A", "B", "C"];
        if let Some(at) = self.klartext.rotary_unknown {
            let missing: Vec<&str> = (0..3)
                .filter(|&i| turned[i] && block.axes[3 + i].is_none())
                .map(|i| letters[i])
                .collect();
            if !missing.is_empty() {
                if !under_plane {
                    // Outside a plane the words are read as they always were.
                    return Ok(false);
                }
                return Err(self.error(
                    line,
                    format!(
                        "this block positions some of the rotary axes, but where {} stands is \
                         not known here: line {at} moved the axes to the plane's solution, which \
                         the control chooses (PLANE without SEQ) and feedopt leaves to the \
                         kinematics; program {} in this block too, or give the PLANE SEQ+ or SEQ-",
                        missing.join(" and "),
                        missing.join(" and ")
                    ),
                ));
            }
            self.klartext.rotary_unknown = None;
        }
        if !under_plane || self.tcp != Tcp::Off {
            return Ok(under_plane);
        }
        let shift = self.offsets.shift();
        let q = [end[3], end[4], end[5]];
        let k = Self::tool_axis_at(kinematics, q, &shift);
        let plane = self.frame_now().r * self.vector;
        let apart = angle_between(&k, &plane);
        if apart > ROTARY_AXIS_TOLERANCE_RAD {
            let degrees = apart.to_degrees();
            let positions: Vec<String> = (0..3)
                .filter(|&i| turned[i] || block.axes[3 + i].is_some())
                .map(|i| {
                    format!(
                        "{} = {}°",
                        letters[i],
                        crate::error::number(q[i] + shift[3 + i])
                    )
                })
                .collect();
            let file = match self.machine.map(|m| m.file.display().to_string()) {
                Some(f) if !f.is_empty() => f,
                _ => "the machine file".to_string(),
            };
            return Err(self.error(
                line,
                format!(
                    "the rotary axes at {} put the tool along {}, but the PLANE of line {} has \
                     its tool axis along {} (workpiece coordinates, {degrees:.4}° apart): the part would \
                     be machined at another angle than the plane its X Y Z are given in; program \
                     the positions of the plane's solution (after PLANE … STAY: L A+Q120 C+Q122, \
                     SEQ+ or SEQ- selecting which), or check the kinematics in {file}",
                    positions.join(", "),
                    direction(&k),
                    self.klartext.plane_line,
                    direction(&plane),
                ),
            ));
        }
        Ok(true)
    }

    /// The rotary positions the control computes for `PLANE … SEQ+` (`positive`) or `SEQ-`
    /// whose tool axis is `k` (workpiece coordinates), from the machine's kinematics and
    /// travel: `None` where there is nothing to choose (a machine with fewer than two rotary
    /// axes; the tool along the C axis, where both solutions are one) or nothing to choose
    /// with (a reader without the machine's kinematics: a warning when the tool is tilted).
    fn sequence_positions(
        &mut self,
        line: usize,
        positive: bool,
        symmetric: bool,
        k: &Vector3<f64>,
    ) -> Result<Option<[Option<f64>; 3]>> {
        let seq = match (symmetric, positive) {
            (false, true) => "SEQ+",
            (false, false) => "SEQ-",
            (true, true) => "SYM+",
            (true, false) => "SYM-",
        };
        let kinematics = self
            .machine
            .and_then(|m| m.kinematics.as_ref().map(|kin| (m, kin)));
        let Some((machine, kinematics)) = kinematics else {
            if (k - Vector3::z()).norm() > 1e-9 {
                self.warn(
                    line,
                    format!(
                        "PLANE … {seq}: which of the rotary axes' two solutions {seq} selects \
                         depends on the machine's kinematics, which the reader was not given: \
                         the solution is left to the kinematics (read the program with a \
                         machine file)"
                    ),
                );
            }
            return Ok(None);
        };
        let shift = self.offsets.shift();
        let current = [3, 4, 5].map(|i| self.pos[i] + shift[i]);
        let travel = [3, 4, 5].map(|i| machine.travel[i]);
        kinematics
            .sequence_positions(k, positive, symmetric, current, travel)
            .map_err(|e| {
                self.error(
                    line,
                    format!(
                        "PLANE … {seq}: {e}; the control refuses it too: program the other \
                         solution, or check the travel in {}",
                        machine.file.display()
                    ),
                )
            })
    }

    fn tcpm(&mut self, line: usize, args: &str) -> Result<()> {
        let compact = klartext::words(args).join(" ").to_ascii_uppercase();
        if compact.contains("AXIS SPAT") {
            return Err(self.error(
                line,
                "FUNCTION TCPM … AXIS SPAT (A B C as spatial angles) is not supported: post \
                 with AXIS POS (rotary axis positions)",
            ));
        }
        if compact.contains("REFPNT CENTER-CENTER") {
            return Err(self.error(
                line,
                "FUNCTION TCPM … REFPNT CENTER-CENTER: the points are the tool's centre, not its \
                 tip, which feedopt's toolpath is; post with REFPNT TIP-TIP",
            ));
        }
        if compact.contains("F CONT") {
            self.warn(
                line,
                "FUNCTION TCPM F CONT (F as the axes' contouring feed) is read as the tool-tip \
                 feed (F TCP)",
            );
        }
        if compact.contains("PATHCTRL VECTOR") {
            self.warn(
                line,
                "FUNCTION TCPM PATHCTRL VECTOR: the orientation between points is taken as the \
                 rotary axes interpolate it (PATHCTRL AXIS)",
            );
        }
        self.no_tcp_on_machine_coordinates(line)?;
        if self.tcp != Tcp::On {
            self.non_tcp_warned = false;
        }
        self.tcp_code = "FUNCTION TCPM".into();
        self.switch_tcp(Tcp::On);
        Ok(())
    }

    fn cycle_def(&mut self, line: usize, args: &str) -> Result<()> {
        // The TNC 640 writes the parameters on `~` lines: part of this block, each error
        // naming the line of its parameter.
        let (mut words, params) =
            klartext::cycle_arguments(args).map_err(|(k, e)| self.error(line + k, e))?;
        // `CYCL DEF 9 .1 …`: the number's decimal part written apart.
        if words.len() >= 2
            && !words[0].contains(['.', ','])
            && words[1].len() > 1
            && words[1].starts_with(['.', ','])
            && words[1][1..].bytes().all(|b| b.is_ascii_digit())
        {
            let part = words.remove(1);
            words[0].push_str(&part);
        }
        let Some(first) = words.first() else {
            return Err(self.error(line, "CYCL DEF without a cycle number"));
        };
        let number: f64 = first
            .replace(',', ".")
            .parse()
            .map_err(|_| self.error(line, format!("CYCL DEF `{first}`: not a cycle number")))?;
        if !(0.0..100_000.0).contains(&number) {
            return Err(self.error(line, format!("CYCL DEF {number}: not a cycle number")));
        }
        let whole = number.trunc() as u32;
        let sub = ((number - number.trunc()) * 10.0).round() as u32;
        if let Some((_, name)) = cycles::HEIDENHAIN_MOVE_ON_DEFINITION
            .iter()
            .find(|(n, _)| *n == whole)
        {
            return Err(self.error(
                line,
                format!(
                    "CYCL DEF {whole} ({name}) moves the tool when it is defined: it runs the \
                     cycle defined before it at each point of its pattern, which feedopt does \
                     not expand; post the points as PATTERN DEF and CYCL CALL PAT, or as CYCL \
                     CALL POS or M99 blocks"
                ),
            ));
        }
        if cycles::HEIDENHAIN_DEFINITION_ONLY
            .iter()
            .any(|(n, _)| *n == whole)
        {
            // Active when defined, moves nothing (tolerance, orientation, contour data, the
            // dynamics tuning): not the cycle a call runs. Its parameters are its own
            // (332's Q395, the tuning mode, is not cycle 200's depth reference Q395): not
            // assigned. The tolerance (`32.1 T0.075`) is said, with how to apply it.
            if whole == 32 && sub == 1 {
                let tol = words[1..].iter().find_map(|w| {
                    let v = w.strip_prefix(['T', 't'])?;
                    klartext::value(v, &self.vars).ok()
                });
                if let Some(t) = tol.filter(|t| t.is_finite() && *t > 0.0) {
                    let text = format!("CYCL DEF 32.1 T{t}");
                    self.warn(line, super::contour_tolerance_note(&text, t));
                }
            }
            return Ok(());
        }
        for p in &params {
            let at = line + p.line;
            if let Some(word) = klartext::feed_word(&p.value) {
                self.vars.set_word(&p.name, word);
                continue;
            }
            let v = klartext::value(&p.value, &self.vars).map_err(|e| {
                self.error(
                    at,
                    format!(
                        "`{}`: {e}; a cycle parameter is a number, a Q parameter or, for a \
                         feed, MAX (FMAX) or AUTO (FAUTO)",
                        p.written
                    ),
                )
            })?;
            self.vars.set(&p.name, v);
        }
        let rest = &words[1..];
        match whole {
            7 => self.datum_shift(line, sub, rest),
            9 => {
                if sub == 1 {
                    let text: String = rest.concat();
                    let seconds = (0..text.len())
                        .filter(|&i| text.is_char_boundary(i))
                        .find_map(|i| {
                            klartext::value(&text[i..], &self.vars).ok().filter(|_| {
                                text[i..].starts_with(|c: char| {
                                    c.is_ascii_digit() || c == '+' || c == '.'
                                })
                            })
                        })
                        .ok_or_else(|| {
                            self.error(line, "CYCL DEF 9.1 without the dwell time (seconds)")
                        })?;
                    if !(0.0..=1e6).contains(&seconds) {
                        return Err(self.error(
                            line,
                            format!("CYCL DEF 9.1: a dwell of {seconds} s is out of range"),
                        ));
                    }
                    self.add_dwell(line, seconds);
                }
                Ok(())
            }
            247 => {
                let preset = self.vars.value("Q339");
                // Activating a preset resets the datum shift of cycle 7 (and mirroring,
                // rotation and scaling, which feedopt refuses anyway): Heidenhain's cycle
                // manuals (TNC 640 / iTNC 530, cycle 247 PRESETTING, its notes) say the
                // control resets them when it activates a preset from the preset table. A
                // Polish shop's TNC programs rely on it (round 22, `fi104.H`: `247` +
                // `CYCL DEF 7.1 IX-60`, a bore; `247` + `CYCL DEF 7.1 IX+60`, the other bore at
                // X+60, where keeping the shift would put it at X0).
                if self.klartext.datum_shift != Vector3::zeros() {
                    self.klartext.datum_shift = Vector3::zeros();
                    self.klartext.tilted_shift = None;
                    self.set_klartext_frame();
                }
                match self.klartext.preset {
                    None => {
                        self.klartext.preset = Some(preset);
                        self.warn(
                            line,
                            format!(
                                "CYCL DEF 247 activates preset {}: the preset table is the \
                                 control's, so the coordinates are read as the program gives \
                                 them",
                                preset.map_or("(Q339 not known)".to_string(), |p| p.to_string())
                            ),
                        );
                        Ok(())
                    }
                    Some(first) if first == preset => Ok(()),
                    Some(_) => Err(self.error(
                        line,
                        "CYCL DEF 247 changes the preset (datum) within the program: the preset \
                         table is the control's, so feedopt cannot place the coordinates that \
                         follow; post one preset per program",
                    )),
                }
            }
            8 | 10 | 11 | 26 | 19 => Err(self.error(
                line,
                format!(
                    "CYCL DEF {whole} ({}) is not supported: post the program without it (datum \
                     shifts as CYCL DEF 7, tilted planes as PLANE SPATIAL)",
                    match whole {
                        8 => "mirror image",
                        10 => "rotation",
                        11 | 26 => "scaling",
                        _ => "working plane by rotary axis angles",
                    }
                ),
            )),
            _ => {
                self.klartext.cycle = Some((whole, line));
                self.klartext.cycle_params = params
                    .iter()
                    .filter_map(|p| p.name.strip_prefix('Q')?.parse().ok())
                    .collect();
                self.klartext.modal_call = false;
                if !cycles::HEIDENHAIN_EXPANDED.contains(&whole) {
                    self.warn(
                        line,
                        format!(
                            "CYCL DEF {whole}: feedopt cannot expand this cycle ({}): calling it \
                             is an error",
                            cycles::expanded_list()
                        ),
                    );
                }
                Ok(())
            }
        }
    }

    /// `CYCL DEF 7.x`: the datum shift.
    fn datum_shift(&mut self, line: usize, sub: u32, words: &[String]) -> Result<()> {
        if sub == 0 {
            return Ok(());
        }
        let mut shift = self.klartext.datum_shift;
        for w in words {
            let upper = w.to_ascii_uppercase();
            if upper.starts_with('#') {
                return Err(self.error(
                    line,
                    format!(
                        "CYCL DEF 7 `{w}`: a datum table line is the control's data; post the \
                         shift as X Y Z values"
                    ),
                ));
            }
            let (incremental, body) = match upper.strip_prefix('I') {
                Some(b) if b.starts_with(['X', 'Y', 'Z']) => (true, b),
                _ => (false, upper.as_str()),
            };
            let axis = match body.chars().next() {
                Some('X') => 0,
                Some('Y') => 1,
                Some('Z') => 2,
                _ => {
                    return Err(self.error(
                        line,
                        format!(
                            "CYCL DEF 7 `{w}`: a datum shift of X, Y or Z is read (rotary \
                             shifts are not supported)"
                        ),
                    ));
                }
            };
            let v = self.klartext_value(line, w, &body[1..])?;
            if !v.is_finite() || v.abs() > MAX_COORDINATE_MM {
                return Err(self.error(line, format!("CYCL DEF 7 `{w}`: out of range")));
            }
            shift[axis] = if incremental { shift[axis] + v } else { v };
        }
        // Changed under a plane: fine only once it is back to 0 (as posts reset it axis by
        // axis before PLANE RESET); anything else that follows first is an error.
        if self.klartext.plane.is_some() && shift != self.klartext.datum_shift {
            self.klartext.tilted_shift = (shift != Vector3::zeros()).then_some(line);
        } else if shift == Vector3::zeros() {
            self.klartext.tilted_shift = None;
        }
        self.klartext.datum_shift = shift;
        self.set_klartext_frame();
        Ok(())
    }

    /// `PATTERN DEF POS1 (X+25 Y+33.5 Z+0) POS2 (…)`.
    fn pattern_def(&mut self, line: usize, args: &str) -> Result<()> {
        let mut points = Vec::new();
        let text = args.to_ascii_uppercase();
        let mut rest = text.trim();
        let mut last = [self.pos[0], self.pos[1], 0.0];
        while !rest.is_empty() {
            let Some(after) = rest.strip_prefix("POS") else {
                let word = rest.split_whitespace().next().unwrap_or(rest);
                return Err(self.error(
                    line,
                    format!(
                        "PATTERN DEF `{word}`: only point patterns (POS1 … POS9) are supported: \
                         post rows, frames and circles as positions"
                    ),
                ));
            };
            let open = after
                .find('(')
                .ok_or_else(|| self.error(line, "PATTERN DEF POS without its `( X Y Z )`"))?;
            let close = after[open..]
                .find(')')
                .map(|c| open + c)
                .ok_or_else(|| self.error(line, "PATTERN DEF: unclosed `(`"))?;
            let mut p = last;
            for w in klartext::words(&after[open + 1..close]) {
                let (incremental, body) = match w.strip_prefix('I') {
                    Some(b) => (true, b.to_string()),
                    None => (false, w.clone()),
                };
                let axis = match body.chars().next() {
                    Some('X') => 0,
                    Some('Y') => 1,
                    Some('Z') => 2,
                    _ => {
                        return Err(self.error(line, format!("PATTERN DEF: unknown word `{w}`")));
                    }
                };
                let v = self.klartext_value(line, &w, &body[1..])?;
                if !v.is_finite() || v.abs() > MAX_COORDINATE_MM {
                    return Err(self.error(line, format!("PATTERN DEF `{w}`: out of range")));
                }
                p[axis] = if incremental { last[axis] + v } else { v };
            }
            points.push(p);
            last = p;
            rest = after[close + 1..].trim();
            if points.len() > cycles::MAX_REPEATS {
                return Err(self.error(
                    line,
                    format!("PATTERN DEF with more than {} points", cycles::MAX_REPEATS),
                ));
            }
        }
        if points.is_empty() {
            return Err(self.error(line, "PATTERN DEF without points"));
        }
        self.klartext.pattern = points;
        Ok(())
    }

    /// `CYCL CALL`, `CYCL CALL PAT`, `CYCL CALL POS X Y Z`.
    fn cycle_call(&mut self, line: usize, args: &str) -> Result<()> {
        let words = klartext::words(args);
        let first = words.first().map(|w| w.to_ascii_uppercase());
        match first.as_deref() {
            Some("PAT") => {
                if self.klartext.pattern.is_empty() {
                    return Err(self.error(line, "CYCL CALL PAT without a PATTERN DEF before it"));
                }
                let points = self.klartext.pattern.clone();
                for p in points {
                    self.cycle_at(line, p)?;
                }
                Ok(())
            }
            Some("POS") => {
                let mut p = [self.pos[0], self.pos[1], 0.0];
                for w in &words[1..] {
                    let upper = w.to_ascii_uppercase();
                    let (incremental, body) = match upper.strip_prefix('I') {
                        Some(b) if b.starts_with(['X', 'Y', 'Z']) => (true, b.to_string()),
                        _ => (false, upper.clone()),
                    };
                    let axis = match body.chars().next() {
                        Some('X') => 0,
                        Some('Y') => 1,
                        Some('Z') => 2,
                        // The positioning feed (FMAX, F…) and M functions: the move is a rapid.
                        _ => continue,
                    };
                    let v = self.klartext_value(line, w, &body[1..])?;
                    let base = if axis < 2 { self.pos[axis] } else { 0.0 };
                    p[axis] = if incremental { base + v } else { v };
                }
                self.cycle_at(line, p)
            }
            _ => self.run_cycle(line, 0.0),
        }
    }

    /// The Q parameter `n` of the cycle, if set, as a number.
    fn q(&self, n: u32) -> Option<f64> {
        self.vars.value(&format!("Q{n}"))
    }

    /// The Q parameter `n` of the cycle, if set: a number, or a feed's `MAX` or `AUTO`.
    fn q_value(&self, n: u32) -> Option<cycles::QValue> {
        let name = format!("Q{n}");
        match self.vars.word(&name) {
            Some("MAX") => Some(cycles::QValue::Max),
            Some(_) => Some(cycles::QValue::Auto),
            None => self.vars.value(&name).map(cycles::QValue::Number),
        }
    }

    /// Calls the cycle at X Y `p[0..2]`, with the surface raised by `p[2]`: up to the cycle's
    /// clearance height first, then over the point at rapid.
    fn cycle_at(&mut self, line: usize, p: [f64; 3]) -> Result<()> {
        if !p
            .iter()
            .all(|v| v.is_finite() && v.abs() <= MAX_COORDINATE_MM)
        {
            return Err(self.error(line, "cycle position out of range"));
        }
        let surface = self.q(203).unwrap_or(0.0) + p[2];
        let clear = self
            .q(200)
            .unwrap_or(0.0)
            .abs()
            .max(self.q(204).unwrap_or(0.0));
        let level = surface + clear;
        if self.pos[2] < level {
            let mut q = self.pos;
            q[2] = level;
            self.push(line, &q, Feed::Rapid);
            self.pos = q;
        }
        if [self.pos[0], self.pos[1]] != [p[0], p[1]] {
            let mut q = self.pos;
            q[0] = p[0];
            q[1] = p[1];
            self.known[0] = true;
            self.known[1] = true;
            self.push(line, &q, Feed::Rapid);
            self.pos = q;
        }
        self.run_cycle(line, p[2])
    }

    /// Runs the defined cycle from the current position, its surface raised by `offset` mm.
    fn run_cycle(&mut self, line: usize, offset: f64) -> Result<()> {
        let Some((number, def_line)) = self.klartext.cycle else {
            return Err(self.error(line, "a cycle call without a CYCL DEF before it"));
        };
        let (steps, notes) = cycles::heidenhain_steps(
            number,
            &|n| self.q_value(n),
            &|n| self.klartext.cycle_params.contains(&n),
            self.klartext.spindle_rpm,
            self.klartext.tool_feed,
            self.tool_diameter,
            offset,
        )
        .map_err(|e| self.error(line, format!("{e} (CYCL DEF at line {def_line})")))?;
        self.cycle_along_tool(line, &format!("cycle {number}"))?;
        for n in notes {
            self.warn(line, format!("cycle {number}: {n}"));
        }
        self.known[2] = true;
        self.warn_unknown(line);
        let from = self.points.len();
        self.run_steps(line, &steps)?;
        if matches!(number, 207 | 209) {
            // Q239: the pitch, negative for a left-hand thread.
            let pitch = self.q(239).filter(|p| *p != 0.0);
            let tap = super::Tap {
                pitch: pitch.map(f64::abs),
                rpm: self.klartext.spindle_rpm,
                left_hand: pitch.is_some_and(|p| p < 0.0),
            };
            self.tapping(
                line,
                format!("CYCL DEF {number} (at line {def_line})"),
                from,
                tap,
            );
        }
        self.tangent = None;
        Ok(())
    }
}

/// The largest angle (radians) between the tool axis that programmed rotary positions give
/// and the one a `PLANE` sets that is read as the same axis: 1e-4 rad, 0.0057°. Posts print
/// angles to 3 or 4 decimals of a degree, the plane's and the axes' each rounded on its own,
/// which puts the two up to about 4e-5 rad apart (0.0005° on each of SPA, SPB, SPC and on each
/// rotary word); a program that contradicts its plane is off by whole degrees.
const ROTARY_AXIS_TOLERANCE_RAD: f64 = 1e-4;

/// The kinematics of the machine the program is read for, where it has two rotary axes (the
/// tool axis follows from their positions), and which of A, B, C it turns.
fn two_rotary_kinematics(
    machine: Option<&MachineContext>,
) -> Option<(&crate::kinematics::Kinematics, [bool; 3])> {
    let kinematics = machine?.kinematics.as_ref()?;
    kinematics.rotary_axes()[1]?;
    let zero = kinematics.angles_from_rotary([0.0; 3]);
    let turned = [0, 1, 2].map(|i| {
        let mut r = [0.0; 3];
        r[i] = 1.0;
        kinematics.angles_from_rotary(r) != zero
    });
    Some((kinematics, turned))
}

/// A direction for a message: `(0, 1, 0)`, components to 6 decimals.
fn direction(v: &Vector3<f64>) -> String {
    let c = |x: f64| crate::base::trimmed(x, 6);
    format!("({}, {}, {})", c(v.x), c(v.y), c(v.z))
}
