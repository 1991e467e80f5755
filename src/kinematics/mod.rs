//! Kinematics: from the path's tool tip P(u) and rotary angles θ(u) to every machine axis.
//!
//! For each axis q at each station this stage gives the position q, and its derivatives along
//! the path parameter u, `dq/du` and `d²q/du²`. Along a moving path (|P'| > 0) they are the
//! seed's *effective tangent* t_q = dq/ds and *effective curvature* K_q = d²q/ds² (eq. 28–39)
//! scaled by the parametrisation:
//!
//! `dq/du = t_q |P'|`,   `d²q/du² = K_q |P'|² + t_q (P'·P'')/|P'|`,
//!
//! so q̇ = t_q V and q̈ = t_q A + K_q V² (eq. 28–39) hold with V = |P'| u̇. Where the tool tip
//! stands still (pure reorientation, |P'| = 0) only the u-form exists; the solver works in u
//! throughout, so nothing divides by |P'|.
//!
//! Machines (each module states its maths and conventions):
//!
//! | kinematics | axes | path coordinates w | module |
//! |---|---|---|---|
//! | xyz | X Y Z | (Px, Py, Pz) | – |
//! | head_head (seed 000) | X Y Z C A | (Px, Py, Pz, θ1 = C, θ2 = A) | [`head_head`] |
//! | table_table_ac / _bc (LinuxCNC xyzac-trt / xyzbc-trt) | X Y Z A C / X Y Z B C | (Px, Py, Pz, T, C) | [`trunnion`] |
//! | table_table_ab (Haas TR-series: xyzac-trt, platter lettered B) | X Y Z A B | (Px, Py, Pz, A, B) | [`trunnion`] |
//! | head_table (like LinuxCNC maxkins) | X Y Z B C | (Px, Py, Pz, B, C) | [`head_table`] |
//! | dresser (seed 001) | X Z B | (Px, ·, Pz, θ) | [`dresser`] |
//! | joint | as named | the axis positions | – |
//!
//! P is the tool tip in program coordinates (mm), angles are in radians in w and in degrees on
//! the axes. [`Kinematics::rotary_angles`] gives the angles of each CL point ([`branch`]),
//! [`Kinematics::axis_positions`] is the inverse kinematics and [`Kinematics::forward`] the
//! forward one.
//!
//! Two independent routes compute the derivatives: the closed forms of seed 000 for the double
//! swivel head ([`head_head::effective`], eq. 31–39), and the generic route, which pushes
//! second-order dual numbers ([`dual::Dual2`]) through the inverse kinematics. Tests hold them
//! to 1e-9 relative agreement.

pub mod branch;
pub mod dresser;
pub mod dual;
pub mod head_head;
pub mod head_table;
pub mod trunnion;

use nalgebra::Vector3;

use crate::error::{Error, Result};
use crate::machine::{Axis, KinematicsSpec, Machine, RotaryTable, TrunnionTilt};
use branch::{Layout, Target};
use dual::{Dual2, Dual3, Real};

pub use crate::base::{MAX_AXES, PATH_DIM, PathJet};

const DEG: f64 = 180.0 / std::f64::consts::PI;

/// Position and u-derivatives of every axis at one station (file units: mm or degrees).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AxisJets {
    /// Axis positions, mm or degrees.
    pub q: [f64; MAX_AXES],
    /// dq/du.
    pub dq: [f64; MAX_AXES],
    /// d²q/du².
    pub ddq: [f64; MAX_AXES],
}

/// The tool tip in program coordinates, the tool axis there (unit, from the tip towards the
/// spindle or holder) and the path angles (radians) of one machine pose: what the forward
/// kinematics gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolPose {
    /// The tool tip, program coordinates, mm.
    pub p: Vector3<f64>,
    /// The unit tool axis.
    pub k: Vector3<f64>,
    /// The path angles, radians.
    pub angles: [f64; 2],
}

/// What the kinematics reads of a cutter-location point (the readers' `ClPoint` is one): the
/// tool tip and tool axis in program coordinates, the rotary axis positions the program gave
/// (`[A, B, C]`, degrees; `None` where it gave the tool vector) and its source line.
pub trait CutterLocation {
    /// The tool tip, program coordinates, mm.
    fn tip(&self) -> Vector3<f64>;
    /// The unit tool axis, from the tip towards the spindle.
    fn tool_axis(&self) -> Vector3<f64>;
    /// Programmed rotary axis positions `[A, B, C]`, degrees.
    fn rotary(&self) -> Option<[f64; 3]>;
    /// The 1-based source line.
    fn line(&self) -> usize;
}

/// A machine's kinematics, ready to evaluate.
#[derive(Debug, Clone, PartialEq)]
pub enum Kinematics {
    /// Three linear axes follow the tool tip.
    Xyz,
    /// Seed 000's double swivel head.
    HeadHead {
        /// Pivot to tool tip, mm.
        d2: f64,
    },
    /// LinuxCNC's xyzac-trt / xyzbc-trt, and the Haas A/B trunnion.
    TableTable(trunnion::Trunnion),
    /// Tilting head B, rotary table C.
    HeadTable(head_table::HeadTable),
    /// Seed 001's dresser: X, Z and B on the profile normal.
    Dresser(dresser::Dresser),
    /// A joint-space path: the path coordinates are the `n` axis positions.
    Joint {
        /// Number of axes.
        n: usize,
    },
    /// X Y Z and a rotary axis, in machine coordinates ([`KinematicsSpec::FourthAxis`]): the
    /// path is (X, Y, Z, θ) itself, θ the rotary axis's position; the tool axis is +z there.
    FourthAxis(crate::machine::FourthAxis),
}

impl Kinematics {
    /// The kinematics of `machine`.
    pub fn new(machine: &Machine) -> Self {
        match machine.kinematics {
            KinematicsSpec::Xyz => Kinematics::Xyz,
            KinematicsSpec::HeadHead { tool_length } => Kinematics::HeadHead { d2: tool_length },
            KinematicsSpec::TableTable { tilt, params } => {
                Kinematics::TableTable(trunnion::Trunnion { tilt, params })
            }
            KinematicsSpec::HeadTable {
                pivot_length,
                table,
            } => Kinematics::HeadTable(head_table::HeadTable {
                pivot_length,
                table,
            }),
            KinematicsSpec::Dresser { tool_length } => {
                Kinematics::Dresser(dresser::Dresser { tool_length })
            }
            KinematicsSpec::Joint => Kinematics::Joint {
                n: machine.axes.len(),
            },
            KinematicsSpec::FourthAxis(r) => Kinematics::FourthAxis(r),
        }
    }

    /// Number of machine axes this kinematics drives.
    pub fn n_axes(&self) -> usize {
        match self {
            Kinematics::Xyz | Kinematics::Dresser(_) => 3,
            Kinematics::FourthAxis(_) => 4,
            Kinematics::HeadHead { .. } | Kinematics::TableTable(_) | Kinematics::HeadTable(_) => 5,
            Kinematics::Joint { n } => *n,
        }
    }

    /// Whether the tool orientation moves any axis (false: pure reorientations take no time).
    pub fn uses_orientation(&self) -> bool {
        !matches!(self, Kinematics::Xyz | Kinematics::Joint { .. })
    }

    /// The machine axis index of path angle 0 and 1 (`None`: no such angle).
    pub fn rotary_axes(&self) -> [Option<usize>; 2] {
        match self {
            Kinematics::Xyz | Kinematics::Joint { .. } => [None, None],
            // Table A: path angles (B − 90°, A), axes X Y Z A B.
            Kinematics::HeadTable(h) if h.table == RotaryTable::A => [Some(4), Some(3)],
            Kinematics::HeadHead { .. } | Kinematics::TableTable(_) | Kinematics::HeadTable(_) => {
                [Some(3), Some(4)]
            }
            Kinematics::Dresser(_) => [Some(2), None],
            Kinematics::FourthAxis(_) => [Some(3), None],
        }
    }

    /// Each rotary axis's position minus its path angle, radians ([`Self::rotary_axes`] says
    /// which axis): zero but for a head–table machine with table A, whose path angle 0 is
    /// B − 90° ([`head_table`]).
    pub fn angle_offsets(&self) -> [f64; 2] {
        match self {
            Kinematics::HeadTable(h) => [h.tilt_offset(), 0.0],
            _ => [0.0; 2],
        }
    }

    /// The path angles (radians) of rotary axis positions `[A, B, C]` in degrees as a program
    /// gives them (never reduced modulo 360°): (C, A) for head_head, (A, C) for
    /// table_table_ac, (B, C) for table_table_bc and head_table, (A, B) for table_table_ab,
    /// (B − 90°, A) for head_table with table A,
    /// (B, 0) for the dresser, (its angle, 0) for a fourth axis, zero for xyz and joint.
    pub fn angles_from_rotary(&self, rotary: [f64; 3]) -> [f64; 2] {
        let [a, b, c] = rotary.map(f64::to_radians);
        match self {
            Kinematics::Xyz | Kinematics::Joint { .. } => [0.0, 0.0],
            Kinematics::HeadHead { .. } => [c, a],
            Kinematics::TableTable(t) => match t.tilt {
                TrunnionTilt::A => [a, c],
                TrunnionTilt::B => [b, c],
                TrunnionTilt::AB => [a, b],
            },
            Kinematics::HeadTable(h) => match h.table {
                RotaryTable::C => [b, c],
                RotaryTable::A => [b - h.tilt_offset(), a],
            },
            Kinematics::Dresser(_) => [b, 0.0],
            Kinematics::FourthAxis(r) => [[a, b, c][r.index()], 0.0],
        }
    }

    /// The unit tool axis in program coordinates for path angles in radians (+z for xyz, joint
    /// and a fourth axis, whose program coordinates are the machine's).
    pub fn tool_axis(&self, angles: [f64; 2]) -> Vector3<f64> {
        let [a0, a1] = angles;
        match self {
            Kinematics::Xyz | Kinematics::Joint { .. } | Kinematics::FourthAxis(_) => Vector3::z(),
            Kinematics::HeadHead { .. } => head_head::orientation(a0, a1),
            Kinematics::TableTable(t) => t.tool_axis(a0, a1),
            Kinematics::HeadTable(h) => h.tool_axis(a0, a1),
            Kinematics::Dresser(d) => d.tool_axis(a0),
        }
    }

    /// The forward kinematics: axis positions (file units, the kinematics' axis order) to the
    /// tool tip in program coordinates, the tool axis and the path angles. `None` for a
    /// joint-space machine, which has no tool tip.
    pub fn forward(&self, q: &[f64]) -> Option<ToolPose> {
        Some(match self {
            Kinematics::Xyz => ToolPose {
                p: Vector3::new(q[0], q[1], q[2]),
                k: Vector3::z(),
                angles: [0.0; 2],
            },
            Kinematics::HeadHead { d2 } => head_head::forward(*d2, q),
            Kinematics::TableTable(t) => t.forward(q),
            Kinematics::HeadTable(h) => h.forward(q),
            Kinematics::Dresser(d) => d.forward(q),
            Kinematics::FourthAxis(_) => ToolPose {
                p: Vector3::new(q[0], q[1], q[2]),
                k: Vector3::z(),
                angles: [q[3].to_radians(), 0.0],
            },
            Kinematics::Joint { .. } => return None,
        })
    }

    /// The path angles (radians) of every CL point, on one continuous branch within the
    /// rotary axes' travel (`axes`: the machine's axes in the kinematics' order; their `travel`
    /// bounds the angles, an empty slice means no travel limits).
    ///
    /// A point with programmed rotary words (`rotary`, tool-tip mode) takes the machine's
    /// rotary axes from them ([`Kinematics::angles_from_rotary`]; no inverse kinematics, never
    /// reduced modulo 360°). A point given by its tool vector `o` is solved by the tool-vector
    /// inverse kinematics, unwrapped by multiples of 2π, on the solution nearest to the previous
    /// point, which must lie within travel; at the singular pose (tool parallel to the C axis)
    /// C keeps its previous value, and within [`branch::POLE_CONE`] of it C is interpolated
    /// across the pass, the tool vector then deviating by at most [`branch::POLE_TOLERANCE`]
    /// ([`branch`] states the rules). A path that cannot be followed continuously within
    /// travel, a programmed position outside travel, or a dresser point off the X–Z plane is
    /// an error naming its CL line.
    pub fn rotary_angles<P: CutterLocation>(
        &self,
        points: &[P],
        axes: &[Axis],
    ) -> Result<Vec<[f64; 2]>> {
        let travel = self.rotary_axes().map(|i| {
            i.and_then(|i| axes.get(i))
                .and_then(|a| a.travel)
                .map(|(lo, hi)| (lo.to_radians(), hi.to_radians()))
        });
        let lines: Vec<usize> = points.iter().map(|p| p.line()).collect();
        let names = match self {
            Kinematics::Xyz => return xyz_angles(points),
            Kinematics::Joint { .. } => return Ok(vec![[0.0; 2]; points.len()]),
            Kinematics::Dresser(d) => return dresser_angles(d, points, travel[0]),
            Kinematics::FourthAxis(r) => return fourth_axis_angles(*r, points, travel[0]),
            Kinematics::HeadHead { .. } => {
                return self.follow(points, &lines, head_head::layout(travel));
            }
            Kinematics::TableTable(t) => t.tilt.letters(),
            Kinematics::HeadTable(h) => match h.table {
                RotaryTable::C => ["B", "C"],
                RotaryTable::A => ["B", "A"],
            },
        };
        let offset = self.angle_offsets();
        let travel = [0, 1].map(|i| travel[i].map(|(lo, hi)| (lo - offset[i], hi - offset[i])));
        self.follow(
            points,
            &lines,
            Layout {
                tilt: 0,
                travel,
                names,
                offset,
            },
        )
    }

    /// The rotary axis positions, degrees as `[A, B, C]`, that a Heidenhain control computes
    /// for a working plane whose tool axis is `k` (program coordinates) under `PLANE … SEQ+`
    /// (`positive`) or `SEQ−` (its Q120–Q122): the solution [`branch::sequence`] picks, from
    /// the positions `current` (`[A, B, C]`, degrees) within the rotary axes' travel `travel`
    /// (`[A, B, C]`, degrees, `None`: unlimited). `Some` for the axes this kinematics turns,
    /// `None` for the others; `Ok(None)` where there are no two solutions to choose from: a
    /// kinematics with fewer than two rotary axes, or `k` along the C axis (tilt 0, any spin).
    /// `Err`: no solution with that sign within travel (the message names the axes, not the
    /// line). `symmetric`: `PLANE … SYM±` instead, the sign taken from the master axis's
    /// symmetry point, the centre of its travel (an `Err` where its travel is not limited).
    pub fn sequence_positions(
        &self,
        k: &Vector3<f64>,
        positive: bool,
        symmetric: bool,
        current: [f64; 3],
        travel: [Option<(f64, f64)>; 3],
    ) -> std::result::Result<Option<[Option<f64>; 3]>, String> {
        let (names, tilt_index) = match self {
            Kinematics::HeadHead { .. } => (["C", "A"], 1),
            Kinematics::TableTable(t) => (t.tilt.letters(), 0),
            Kinematics::HeadTable(h) => match h.table {
                RotaryTable::C => (["B", "C"], 0),
                RotaryTable::A => (["B", "A"], 0),
            },
            _ => return Ok(None),
        };
        let letter = |name: &str| match name {
            "A" => 0,
            "B" => 1,
            _ => 2,
        };
        let offset = self.angle_offsets();
        let layout = Layout {
            tilt: tilt_index,
            travel: [0, 1].map(|i| {
                travel[letter(names[i])]
                    .map(|(lo, hi)| (lo.to_radians() - offset[i], hi.to_radians() - offset[i]))
            }),
            names,
            offset,
        };
        let (tilt, spin) = match self {
            Kinematics::HeadHead { .. } => head_head::tool_vector_ik(k),
            Kinematics::TableTable(t) => t.tool_vector_ik(k),
            Kinematics::HeadTable(h) => h.tool_vector_ik(k),
            _ => return Ok(None),
        };
        if spin.is_none() {
            // The tool along the C axis: both solutions are one (tilt 0).
            return Ok(None);
        }
        let master = names[tilt_index];
        let about = if symmetric {
            let (lo, hi) = travel[letter(master)].ok_or_else(|| {
                format!(
                    "SYM takes its sign from the symmetry point of {master}, the centre of its                      travel, and {master} has no travel limits"
                )
            })?;
            0.5 * (lo + hi)
        } else {
            0.0
        };
        let angles = branch::sequence(
            tilt,
            spin,
            &layout,
            positive,
            about,
            self.angles_from_rotary(current),
        )?;
        let mut out = [None; 3];
        for (i, (name, angle)) in names.iter().zip(angles).enumerate() {
            out[letter(name)] = Some(layout.position(i, angle));
        }
        Ok(Some(out))
    }

    /// [`branch::follow`] for a two-rotary kinematics.
    fn follow<P: CutterLocation>(
        &self,
        points: &[P],
        lines: &[usize],
        layout: Layout,
    ) -> Result<Vec<[f64; 2]>> {
        let targets: Vec<Target> = points
            .iter()
            .map(|p| match p.rotary() {
                Some(r) => Target::Programmed(self.angles_from_rotary(r)),
                None => {
                    let (tilt, spin) = match self {
                        Kinematics::HeadHead { .. } => head_head::tool_vector_ik(&p.tool_axis()),
                        Kinematics::TableTable(t) => t.tool_vector_ik(&p.tool_axis()),
                        Kinematics::HeadTable(h) => h.tool_vector_ik(&p.tool_axis()),
                        _ => (0.0, None),
                    };
                    Target::Vector {
                        k: p.tool_axis(),
                        tilt,
                        spin,
                    }
                }
            })
            .collect();
        branch::follow(&targets, lines, &layout, &|a| self.tool_axis(a))
    }

    /// Axis positions for path coordinates `w` in any [`Real`] type (eq. 27 for head_head).
    /// Rotary axes are returned in degrees.
    pub fn axis_positions<T: Real>(&self, w: [T; PATH_DIM], out: &mut [T; MAX_AXES]) {
        match self {
            Kinematics::Xyz => {
                out[0] = w[0];
                out[1] = w[1];
                out[2] = w[2];
            }
            Kinematics::HeadHead { d2 } => head_head::axis_positions(*d2, w, out),
            Kinematics::TableTable(t) => t.axis_positions(w, out),
            Kinematics::HeadTable(h) => h.axis_positions(w, out),
            Kinematics::Dresser(d) => d.axis_positions(w, out),
            Kinematics::FourthAxis(_) => {
                out[0] = w[0];
                out[1] = w[1];
                out[2] = w[2];
                out[3] = w[3].scale(rad_to_deg());
            }
            Kinematics::Joint { n } => out[..*n].copy_from_slice(&w[..*n]),
        }
    }

    /// Every axis's q, dq/du, d²q/du² by the generic route (dual numbers through
    /// [`Kinematics::axis_positions`]).
    pub fn axis_jets_generic(&self, w: &PathJet) -> AxisJets {
        let wd: [Dual2; PATH_DIM] =
            std::array::from_fn(|i| Dual2::new(w.value[i], w.d1[i], w.d2[i]));
        let mut q = [Dual2::cst(0.0); MAX_AXES];
        self.axis_positions(wd, &mut q);
        let mut out = AxisJets::default();
        for i in 0..self.n_axes() {
            out.q[i] = q[i].v;
            out.dq[i] = q[i].d;
            out.ddq[i] = q[i].dd;
        }
        out
    }

    /// Every axis's d³q/du³ (generic route: third-order dual numbers through
    /// [`Kinematics::axis_positions`]), given the path's jet `w` and its third derivative `d3`.
    /// Axis jerk is q⃛ = q''' u̇³ + 3 q'' u̇ ü + q' u⃛ (issue 6).
    pub fn axis_third_derivatives(&self, w: &PathJet, d3: &[f64; PATH_DIM]) -> [f64; MAX_AXES] {
        let wd: [Dual3; PATH_DIM] =
            std::array::from_fn(|i| Dual3::new(w.value[i], w.d1[i], w.d2[i], d3[i]));
        let mut q = [Dual3::cst(0.0); MAX_AXES];
        self.axis_positions(wd, &mut q);
        std::array::from_fn(|i| if i < self.n_axes() { q[i].ddd } else { 0.0 })
    }

    /// Every axis's q, dq/du, d²q/du²: the closed forms of seed 000 (eq. 31–39) where the tool
    /// tip moves on a head_head machine, the generic route everywhere else.
    pub fn axis_jets(&self, w: &PathJet) -> AxisJets {
        if let Kinematics::HeadHead { d2 } = self {
            if let Some(eff) = head_head::effective(*d2, w) {
                let mut out = eff.to_u_derivatives(w);
                let mut q = [0.0; MAX_AXES];
                self.axis_positions(w.value, &mut q);
                out.q = q;
                return out;
            }
        }
        self.axis_jets_generic(w)
    }
}

/// Seed 000's effective tangents t_q = dq/ds and effective curvatures K_q = d²q/ds² of every
/// axis at one point of a moving path (eq. 28–39; rotary axes in degrees).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Effective {
    /// Effective tangents t_q = dq/ds.
    pub t: [f64; MAX_AXES],
    /// Effective curvatures K_q = d²q/ds².
    pub k: [f64; MAX_AXES],
}

impl Effective {
    /// Converts arc-length derivatives to u-derivatives: `dq/du = t|P'|`,
    /// `d²q/du² = K|P'|² + t (P'·P'')/|P'|`.
    pub fn to_u_derivatives(&self, w: &PathJet) -> AxisJets {
        let (dp, ddp) = tip_derivatives(w);
        let speed = dp.norm();
        let along = dp.dot(&ddp) / speed;
        let mut out = AxisJets::default();
        for i in 0..MAX_AXES {
            out.dq[i] = self.t[i] * speed;
            out.ddq[i] = self.k[i] * speed * speed + self.t[i] * along;
        }
        out
    }

    /// The inverse of [`Effective::to_u_derivatives`]; `None` where the tip stands still.
    pub fn from_u_derivatives(j: &AxisJets, w: &PathJet) -> Option<Effective> {
        let (dp, ddp) = tip_derivatives(w);
        let speed = dp.norm();
        if speed <= f64::MIN_POSITIVE {
            return None;
        }
        let along = dp.dot(&ddp) / speed;
        let mut e = Effective::default();
        for i in 0..MAX_AXES {
            e.t[i] = j.dq[i] / speed;
            e.k[i] = (j.ddq[i] - e.t[i] * along) / (speed * speed);
        }
        Some(e)
    }
}

/// A three-axis machine's (no) angles: a tool vector other than +z is an error naming its CL
/// line. The tool of such a machine cannot tilt; reading the point with the tool along +Z
/// would put the tool tip where the program does not (a CL file's `TLAXIS/0,-1,0` or
/// `GOTO/x,y,z,i,j,k` for a horizontal tool), quietly.
fn xyz_angles<P: CutterLocation>(points: &[P]) -> Result<Vec<[f64; 2]>> {
    if let Some(p) = points
        .iter()
        .find(|p| (p.tool_axis() - Vector3::z()).norm() > 1e-9)
    {
        return Err(Error::Infeasible(format!(
            "CL point at line {}: a tool vector ({}, {}, {}) on a machine of type xyz, whose \
             tool stays along +Z: give a machine file with the rotary axes that tilt it \
             (head_head, table_table, head_table), or a toolpath with the tool along +Z",
            p.line(),
            p.tool_axis().x,
            p.tool_axis().y,
            p.tool_axis().z
        )));
    }
    Ok(vec![[0.0; 2]; points.len()])
}

/// A fourth axis's angle at every CL point: its programmed position (0 where the program never
/// turns it), which must lie within its travel; a tool vector other than +z is an error (such a
/// machine's program coordinates are its own, the tool always along +z).
fn fourth_axis_angles<P: CutterLocation>(
    r: crate::machine::FourthAxis,
    points: &[P],
    travel: Option<(f64, f64)>,
) -> Result<Vec<[f64; 2]>> {
    points
        .iter()
        .map(|p| {
            let line = p.line();
            if (p.tool_axis() - Vector3::z()).norm() > 1e-9 {
                return Err(Error::Infeasible(format!(
                    "CL point at line {line}: a tool vector ({}, {}, {}) on a machine of type \
                     xyz{}, whose tool stays along +Z (its programs give the {} axis's \
                     position instead)",
                    p.tool_axis().x,
                    p.tool_axis().y,
                    p.tool_axis().z,
                    r.letter().to_ascii_lowercase(),
                    r.letter()
                )));
            }
            let theta = p.rotary().map_or(0.0, |q| q[r.index()].to_radians());
            if !branch::within(theta, travel) {
                let (lo, hi) = travel.unwrap_or_default();
                return Err(Error::Infeasible(format!(
                    "CL point at line {line}: programmed {} = {}° is outside its travel \
                     [{}, {}]°",
                    r.letter(),
                    theta.to_degrees(),
                    lo.to_degrees(),
                    hi.to_degrees()
                )));
            }
            Ok([theta, 0.0])
        })
        .collect()
}

/// The dresser's B along the path: programmed, or the profile normal's angle unwrapped nearest
/// to the previous point within travel. Points must lie in the X–Z plane.
fn dresser_angles<P: CutterLocation>(
    d: &dresser::Dresser,
    points: &[P],
    travel: Option<(f64, f64)>,
) -> Result<Vec<[f64; 2]>> {
    /// Largest |Py| (mm) and |o_y| accepted as "in the X–Z plane".
    const OFF_PLANE: f64 = 1e-6;
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(points.len());
    for p in points {
        let line = p.line();
        let prev = out.last().map_or(0.0, |a| a[0]);
        if p.tip().y.abs() > OFF_PLANE {
            return Err(Error::Infeasible(format!(
                "CL point at line {line}: a dresser works in the X–Z plane, but this point has \
                 y = {} mm",
                p.tip().y
            )));
        }
        let theta = match p.rotary() {
            Some(r) => {
                let b = r[1].to_radians();
                if !branch::within(b, travel) {
                    let (lo, hi) = travel.unwrap_or_default();
                    return Err(Error::Infeasible(format!(
                        "CL point at line {line}: programmed B = {}° is outside its travel \
                         [{}, {}]°",
                        r[1],
                        lo.to_degrees(),
                        hi.to_degrees()
                    )));
                }
                b
            }
            None => {
                if p.tool_axis().y.abs() > OFF_PLANE {
                    return Err(Error::Infeasible(format!(
                        "CL point at line {line}: a dresser works in the X–Z plane, but this \
                         point's tool vector has y = {}",
                        p.tool_axis().y
                    )));
                }
                let raw = d.tool_vector_ik(&p.tool_axis()).ok_or_else(|| {
                    Error::Infeasible(format!(
                        "CL point at line {line}: the tool vector has no direction in the X–Z plane"
                    ))
                })?;
                // Continuous: the shift nearest the previous point (the first: nearest zero,
                // within travel), which must lie within travel.
                let theta = if out.is_empty() {
                    branch::fit(raw, 0.0, travel)
                } else {
                    branch::fit(raw, prev, None).filter(|t| branch::within(*t, travel))
                };
                theta.ok_or_else(|| {
                    let (lo, hi) = travel.unwrap_or_default();
                    Error::Infeasible(format!(
                        "CL point at line {line}: following the profile normal continuously \
                         needs B = {:.4}°, outside its travel [{}, {}]°",
                        branch::fit(raw, prev, None).unwrap_or(raw).to_degrees(),
                        lo.to_degrees(),
                        hi.to_degrees()
                    ))
                })?
            }
        };
        out.push([theta, 0.0]);
    }
    Ok(out)
}

/// P'(u) and P''(u) of a path jet.
pub fn tip_derivatives(w: &PathJet) -> (Vector3<f64>, Vector3<f64>) {
    (
        Vector3::new(w.d1[0], w.d1[1], w.d1[2]),
        Vector3::new(w.d2[0], w.d2[1], w.d2[2]),
    )
}

pub(crate) fn rad_to_deg() -> f64 {
    DEG
}
