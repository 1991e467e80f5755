//! The material stage (seed 003): a dexel stock model tells how much material the tool engages
//! along the path, and process limits turn that into feed caps.
//!
//! Plain data in, plain data out, between the toolpath and the constraints:
//!
//! 1. [`simulate`]: a [`Stock`] (box or cylinder, workpiece coordinates) as Z-dexels
//!    ([`dexel`]), the program's [`Tool`]s (flat, ball or bull-nose end mills; each move is
//!    cut with the tool in the spindle there, [`Material::tool_at`], from the program's tool
//!    changes and the [`tooltable`]), and the toolpath's CL moves
//!    cut into sample steps fixed by the grid; each step's swept volume removes material
//!    ([`cut`]: exact for a vertical tool axis, conservative for a tilted one) and yields a
//!    [`cut::Sample`]: removed volume ΔV, engaged cross-section A = ΔV/Δs normal to the feed
//!    (MRR = A·V), axial depth a_p, radial engagement a_e and engagement angle φ.
//! 2. [`FeedLimits::new`]: the [`ProcessLimits`] (chip load, MRR, power, air feed; each
//!    optional) as a piecewise-constant cap on the tool-tip feed V along every CL move, with
//!    that move's tool's D and flutes.
//! 3. [`FeedLimits::attach`]: those caps on the spans of a built path, as
//!    [`crate::geometry::ProcessCaps`] in each span's u. Their breaks become stations
//!    ([`crate::constraints::stations`]) and each cap one more upper bound on b = u̇² at the
//!    stations, `|P'|² b ≤ V_max²`, beside the axis limits (named [`ProcessLimit`] in the
//!    binding table); the re-simulation checks them like the programmed feed.
//!
//! Work is bounded before it starts: at most [`MAX_DEXELS`] dexels, [`MAX_SAMPLES`] samples
//! and [`MAX_WORK`] dexel updates (the dexels under each step's tool, times the poses of a
//! tilted step), estimated from the path before any material is cut.

pub mod check;
pub mod cut;
pub mod dexel;
pub mod process;
pub mod program;
pub mod stock;
pub mod tool;
pub mod tooltable;

use std::path::Path;

pub use cut::Sample;
pub use dexel::Dexels;
pub use process::{ProcessLimit, ProcessLimits};
pub use stock::Stock;
pub use tool::Tool;

use crate::error::{Error, Result};
use crate::geometry::{self, ProcessCaps, SpanKind};
use crate::toolpath::{ToolSelect, Toolpath};

/// The most dexels a model may have (40 bytes each once a cut reaches its tile, and more
/// where an undercut splits one, [`dexel`]): 10 million, e.g. 316 × 316 mm at 0.1 mm.
pub const MAX_DEXELS: f64 = 1e7;

/// The most sample steps along a path: 10 million.
pub const MAX_SAMPLES: f64 = 1e7;

/// The most dexel updates (Σ over steps of the dexels under the step's tool × its poses): 2e9,
/// about a minute on one core.
pub const MAX_WORK: f64 = 2e9;

/// Default cells across the tool diameter: the cell size is D/50 (0.2 mm for a 10 mm tool).
pub const CELLS_PER_DIAMETER: f64 = 50.0;

/// Steps cut together ([`simulate`]): the threads meet once per batch.
pub const STEP_BATCH: usize = 256;

/// Caps of neighbouring samples within this fraction of each other merge into their minimum
/// (fewer stations, never a higher feed).
pub const MERGE_TOLERANCE: f64 = 0.01;

/// Grid resolution and sampling.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct CutOptions {
    /// Dexel cell size, mm (`None`: D / [`CELLS_PER_DIAMETER`]).
    pub cell: Option<f64>,
    /// Sample step along the path, mm (`None`: the larger of 5 cells and D/8, so each sample's
    /// A averages the grid's discretisation over many cells).
    pub step: Option<f64>,
}

impl CutOptions {
    /// The cell size for `tool`, mm.
    pub fn cell_for(&self, tool: &Tool) -> f64 {
        self.cell.unwrap_or(tool.diameter / CELLS_PER_DIAMETER)
    }

    /// The sample step for `tool`, mm.
    pub fn step_for(&self, tool: &Tool) -> f64 {
        self.step
            .unwrap_or_else(|| (5.0 * self.cell_for(tool)).max(tool.diameter / 8.0))
    }
}

/// A tool of the program and the moves it cuts.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ToolUse {
    /// The first CL move it cuts (the move ending at this CL point); it cuts every move up to
    /// the next tool's first. The first tool's is 0: it also cuts the moves before the
    /// program's first tool selection.
    pub first_move: usize,
    /// The program line that selects it (0: the program selects none; the machine file's or
    /// the options' tool).
    pub line: usize,
    /// What the program writes (`T2`, `CUTTER/10,2`, …), if anything.
    pub select: Option<ToolSelect>,
    /// The tool.
    pub tool: Tool,
}

/// Everything the material stage needs: stock, tools, process limits and resolution.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Material {
    /// The blank, in workpiece coordinates.
    pub stock: Stock,
    /// The cutters in the order the program uses them (at least one; `first_move` increasing
    /// from 0).
    pub tools: Vec<ToolUse>,
    /// The process limits (each optional). Its `spindle_speed` is the speed of the moves
    /// the program sets none for (all of them when [`Material::spindle`] is empty).
    pub process: ProcessLimits,
    /// The program's spindle speeds, each from its first move on (`first_move` increasing):
    /// empty when an option gives the speed or the program sets none.
    pub spindle: Vec<SpindleUse>,
    /// Grid resolution and sample step.
    pub options: CutOptions,
}

/// A spindle speed of the program and the moves it runs: from the move ending at CL point
/// `first_move` to the next change.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SpindleUse {
    /// The CL point that ends its first move.
    pub first_move: usize,
    /// The program line that sets it.
    pub line: usize,
    /// The speed, rpm.
    pub rpm: f64,
}

impl Material {
    /// The material model of one tool for the whole program.
    pub fn single(
        stock: Stock,
        tool: Tool,
        process: ProcessLimits,
        options: CutOptions,
    ) -> Material {
        Material {
            stock,
            tools: vec![ToolUse {
                first_move: 0,
                line: 0,
                select: None,
                tool,
            }],
            process,
            spindle: Vec::new(),
            options,
        }
    }

    /// The spindle speed on the move ending at CL point `k`, rpm: the program's speed in force
    /// there, else (before the program sets one, or without any) `process.spindle_speed`.
    pub fn spindle_at(&self, k: usize) -> Option<f64> {
        let i = self.spindle.partition_point(|s| s.first_move <= k);
        match i {
            0 => self.process.spindle_speed,
            _ => Some(self.spindle[i - 1].rpm),
        }
    }

    /// The process limits on the move ending at CL point `k`: [`Material::process`] with that
    /// move's spindle speed ([`Material::spindle_at`]).
    pub fn process_at(&self, k: usize) -> ProcessLimits {
        ProcessLimits {
            spindle_speed: self.spindle_at(k),
            ..self.process
        }
    }

    /// The first tool.
    pub fn tool(&self) -> &Tool {
        &self.tools[0].tool
    }

    /// The index into [`Material::tools`] of the tool that cuts the move ending at CL point `k`.
    pub fn tool_index(&self, k: usize) -> usize {
        self.tools
            .partition_point(|t| t.first_move <= k)
            .saturating_sub(1)
    }

    /// The tool that cuts the move ending at CL point `k`.
    pub fn tool_at(&self, k: usize) -> &Tool {
        &self.tools[self.tool_index(k)].tool
    }

    /// The dexel cell, mm: the option, else D/[`CELLS_PER_DIAMETER`] of the smallest tool (one
    /// grid for every tool).
    pub fn cell(&self) -> f64 {
        let smallest = self
            .tools
            .iter()
            .map(|t| &t.tool)
            .min_by(|a, b| a.diameter.total_cmp(&b.diameter))
            .unwrap_or(&self.tools[0].tool);
        self.options.cell_for(smallest)
    }

    /// The sample step of the moves `tool` cuts, mm: the option, else the larger of 5 cells
    /// and D/8.
    pub fn step_for(&self, tool: &Tool) -> f64 {
        self.options
            .step
            .unwrap_or_else(|| (5.0 * self.cell()).max(tool.diameter / 8.0))
    }
}

/// The result of a cut: every sample's engagement and the final stock.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// Samples in path order.
    pub samples: Vec<Sample>,
    /// The stock after the last move.
    pub dexels: Dexels,
    /// The dexel model's volume before the first move, mm³.
    pub initial_volume: f64,
    /// The dexel model's volume after the last move, mm³.
    pub final_volume: f64,
    /// Σ ΔV over the samples, mm³ (equals initial − final up to rounding).
    pub removed_volume: f64,
    /// Cell size (x, y) used, mm.
    pub cell: (f64, f64),
    /// Sample step along the path, mm.
    pub step: f64,
    /// Dexel updates done (the estimate checked against [`MAX_WORK`]).
    pub work: f64,
}

/// The toolpath with every CL point's tool axis in workpiece coordinates. A G-code program in
/// tool-tip mode gives rotary words, not a tool vector (its reader leaves +Z in the points),
/// so the machine's kinematics turn the programmed angles into the axis, on the branch the
/// solve follows ([`crate::kinematics::Kinematics::rotary_angles`]); between CL points the cut interpolates the
/// axis as for APT vectors. Borrowed unchanged when no point has rotary words.
pub fn tool_axes<'a>(
    tp: &'a Toolpath,
    machine: &crate::machine::Machine,
) -> Result<std::borrow::Cow<'a, Toolpath>> {
    use crate::kinematics::Kinematics;
    if let crate::machine::KinematicsSpec::FourthAxis(r) = machine.kinematics
        && let Some(p) = tp
            .points
            .iter()
            .find(|p| p.rotary.is_some_and(|q| q[r.index()] != 0.0))
    {
        // The part turns with the axis: its coordinates are not the program's (machine) ones.
        return Err(Error::Usage(format!(
            "{}: line {} turns the {} axis, and with it the part; the material model cuts in the \
             part's coordinates, which a four-axis program (in machine coordinates) does not \
             give: leave out the stock",
            tp.source.display(),
            p.line,
            r.letter()
        )));
    }
    if machine.kinematics == crate::machine::KinematicsSpec::Joint
        || !tp.points.iter().any(|p| p.rotary.is_some())
    {
        return Ok(std::borrow::Cow::Borrowed(tp));
    }
    let kin = Kinematics::new(machine);
    let angles = kin.rotary_angles(&tp.points, &machine.axes)?;
    let mut out = tp.clone();
    for (p, a) in out.points.iter_mut().zip(&angles) {
        if p.rotary.is_some() {
            p.o = kin.tool_axis(*a);
        }
    }
    Ok(std::borrow::Cow::Owned(out))
}

/// Checks the resolution and estimates the work of cutting `tp` with `m` (module doc),
/// refusing what exceeds the bounds before anything is allocated.
pub fn estimate_work(tp: &Toolpath, m: &Material) -> Result<f64> {
    let cell = m.cell();
    let usage = |what: String| Error::Usage(what);
    for t in &m.tools {
        let (d, step) = (t.tool.diameter, m.step_for(&t.tool));
        if !(cell.is_finite() && cell >= 1e-4 && cell <= d) {
            return Err(usage(format!(
                "dexel cell {cell} mm: give a cell from 0.0001 mm to the tool diameter ({d} mm)"
            )));
        }
        if !(step.is_finite() && step >= cell && step <= 100.0 * d) {
            return Err(usage(format!(
                "sample step {step} mm: give a step from the cell size ({cell} mm) to 100 tool \
                 diameters ({d} mm)"
            )));
        }
    }
    let (nx, ny) = Dexels::shape(&m.stock, cell);
    if nx * ny > MAX_DEXELS {
        return Err(usage(format!(
            "the stock needs {:.3e} dexels at {cell} mm (at most {MAX_DEXELS:e}): give a coarser \
             cell",
            nx * ny
        )));
    }
    let mut samples = 0.0;
    for k in 1..tp.points.len() {
        let (a, b) = (&tp.points[k - 1], &tp.points[k]);
        if a.o.dot(&b.o) < -0.9998 {
            return Err(Error::parse(
                &tp.source,
                b.line,
                "the tool axis turns by 179° or more in one move: the material model cannot \
                 tell which way it turns; split the move",
            ));
        }
        let tool = m.tool_at(k);
        let e = (b.p - a.p).norm() + tool.flute_length * crate::base::angle_between(&a.o, &b.o);
        samples += (e / m.step_for(tool)).ceil();
    }
    if samples > MAX_SAMPLES {
        return Err(usage(format!(
            "the path needs {samples:.3e} samples at a step of {} mm (at most \
             {MAX_SAMPLES:e}): give a longer sample step",
            m.step_for(m.tool())
        )));
    }
    let mut work = 0.0;
    for k in 1..tp.points.len() {
        let tool = m.tool_at(k);
        let delta = cut::pose_spacing(tool, cell);
        let n = cut::steps_of_move(tp, k, tool, m.step_for(tool));
        for s in 0..n {
            let st = cut::step_of_move(tp, k, s, n);
            let poses = st.poses(tool, delta);
            let b = st.bounds(tool, poses);
            let cells = ((b[2] - b[0]) / cell + 1.0) * ((b[3] - b[1]) / cell + 1.0);
            work += cells * poses as f64;
        }
        if work > MAX_WORK {
            return Err(usage(format!(
                "cutting the path at {cell} mm takes more than {MAX_WORK:e} dexel updates (by \
                 line {}): give a coarser cell",
                tp.points[k].line
            )));
        }
    }
    Ok(work)
}

/// Cuts the stock along the toolpath (module doc): every CL move in order, sample step by
/// sample step, each with the tool that cuts it ([`Material::tool_at`]).
pub fn simulate(tp: &Toolpath, m: &Material) -> Result<Simulation> {
    m.stock
        .validate()
        .map_err(|e| Error::Usage(format!("stock: {e}")))?;
    let work = estimate_work(tp, m)?;
    let cell = m.cell();
    let mut dexels = Dexels::new(&m.stock, cell);
    let initial_volume = dexels.volume();
    // The steps run one after the other, each spreading its rows over the thread pool: from
    // one of the pool's own threads (`rayon::scope`), so that a step hands its rows to the
    // others directly rather than waking the pool from outside and sleeping until it is done
    // (9,344 steps on the LinuxCNC impeller: 14 % of the time went to that).
    //
    // The steps go to the cut in batches of up to [`STEP_BATCH`] (one tool's): the bands of
    // rows they cover are cut in parallel, each band taking the batch's steps in order
    // ([`cut::cut_steps`]).
    let samples = rayon::scope(|_| {
        let mut samples = Vec::new();
        let mut shared = cut::SharedPose::new(dexels.ny);
        let mut current = m.tool_index(1.min(tp.points.len()));
        // The batch: its steps and, per step, (CL point, step, steps of the move).
        let mut batch: Vec<cut::Step> = Vec::with_capacity(STEP_BATCH);
        let mut meta: Vec<(usize, usize, usize)> = Vec::with_capacity(STEP_BATCH);
        let mut flush = |batch: &mut Vec<cut::Step>,
                         meta: &mut Vec<(usize, usize, usize)>,
                         which: usize,
                         shared: &mut cut::SharedPose,
                         dexels: &mut Dexels| {
            if batch.is_empty() {
                return;
            }
            let tool = &m.tools[which].tool;
            let delta = cut::pose_spacing(tool, dexels.hx.min(dexels.hy));
            let cut = cut::cut_steps(dexels, tool, batch, delta, shared);
            for (mut sample, &(k, s, n)) in cut.into_iter().zip(meta.iter()) {
                let (feed, rapid) = cut::move_feed(tp, k);
                sample.point = k;
                sample.t = [s as f64 / n as f64, (s + 1) as f64 / n as f64];
                sample.line = tp.points[k].line;
                sample.rapid = rapid;
                sample.programmed_feed = feed;
                samples.push(sample);
            }
            batch.clear();
            meta.clear();
        };
        for k in 1..tp.points.len() {
            let which = m.tool_index(k);
            if which != current {
                // Another tool: the last pose's crossings were the old tool's.
                flush(&mut batch, &mut meta, current, &mut shared, &mut dexels);
                shared = cut::SharedPose::new(dexels.ny);
                current = which;
            }
            let tool = &m.tools[which].tool;
            let n = cut::steps_of_move(tp, k, tool, m.step_for(tool));
            for s in 0..n {
                batch.push(cut::step_of_move(tp, k, s, n));
                meta.push((k, s, n));
                if batch.len() == STEP_BATCH {
                    flush(&mut batch, &mut meta, current, &mut shared, &mut dexels);
                }
            }
        }
        flush(&mut batch, &mut meta, current, &mut shared, &mut dexels);
        samples
    });
    let final_volume = dexels.volume();
    let removed_volume = samples.iter().map(|s| s.removed).sum();
    Ok(Simulation {
        samples,
        cell: (dexels.hx, dexels.hy),
        dexels,
        initial_volume,
        final_volume,
        removed_volume,
        step: m.step_for(m.tool()),
        work,
    })
}

/// A feed piece of one CL move: from fraction `t` of the move on, the cap `cap` (mm/s) set by
/// `by`; `None`: no process limit there (the programmed feed applies).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeedPiece {
    /// Fraction of the move (0 to 1) from which this piece holds.
    pub t: f64,
    /// The cap (mm/s) and the limit setting it; `None`: no process limit here.
    pub cap: Option<(f64, ProcessLimit)>,
}

/// The process caps of every CL move: a piecewise-constant function of the path, fixed by the
/// material sampling (not by any solver's stations).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FeedLimits {
    /// `moves[k]`: the pieces of the move ending at CL point k (empty for k = 0 and where the
    /// tool does not move).
    pub moves: Vec<Vec<FeedPiece>>,
}

impl FeedLimits {
    /// The caps of a simulation under `m`'s process limits. Where the tool cuts air (ΔV = 0)
    /// and no air feed is given, the cap is infinite (the machine's limits apply); where it
    /// cuts and no cutting limit is given, there is no process cap (`None`). Neighbouring
    /// samples of one move whose caps are within [`MERGE_TOLERANCE`] merge into their minimum.
    pub fn new(sim: &Simulation, m: &Material, points: usize) -> FeedLimits {
        let mut moves: Vec<Vec<FeedPiece>> = vec![Vec::new(); points];
        for s in &sim.samples {
            let cap = if s.removed <= 0.0 {
                Some((
                    m.process.air_feed.unwrap_or(f64::INFINITY),
                    ProcessLimit::Air,
                ))
            } else {
                let tool = m.tool_at(s.point);
                m.process_at(s.point).bound(s, tool.diameter, tool.flutes)
            };
            let pieces = &mut moves[s.point];
            if let Some(last) = pieces.last_mut() {
                let merge = match (last.cap, cap) {
                    (None, None) => true,
                    (Some((a, ka)), Some((b, kb))) => {
                        (a == b) || (ka == kb && (a - b).abs() <= MERGE_TOLERANCE * a.min(b))
                    }
                    _ => false,
                };
                if merge {
                    if let (Some(a), Some(b)) = (last.cap, cap) {
                        if b.0 < a.0 {
                            last.cap = Some(b);
                        }
                    }
                    continue;
                }
            }
            pieces.push(FeedPiece { t: s.t[0], cap });
        }
        FeedLimits { moves }
    }

    /// Puts the caps on the moving spans of `path` (built from `tp`) as
    /// [`ProcessCaps`]: a piece's cap is min(process cap, `feed_max`), or where it has none the
    /// CL move's own cap (programmed feed, override, maximum feed). Errors where a span's knots
    /// are not CL points (a dresser profile refitted by biarcs).
    pub fn attach(
        &self,
        path: &mut geometry::Path,
        tp: &Toolpath,
        feed_max: Option<f64>,
    ) -> Result<()> {
        let fmax = feed_max.unwrap_or(f64::INFINITY);
        for span in &mut path.spans {
            if span.kind != SpanKind::Moving {
                continue;
            }
            if span.points.len() != span.spline.knots().len() {
                return Err(Error::Usage(format!(
                    "{}: process limits need the CL points as the path's knots; a dresser \
                     profile refitted by biarcs has none (give --tolerance 0)",
                    tp.source.display()
                )));
            }
            let knots = span.spline.knots().to_vec();
            let mut pc = ProcessCaps::default();
            // The knots at CL points (the geometry inserts others on the programmed chords,
            // geometry::INSERTED): the moves between two of them map onto their u range.
            let cl: Vec<usize> = (0..knots.len())
                .filter(|&k| span.points[k] != geometry::INSERTED)
                .collect();
            for w in cl.windows(2) {
                let (ka, kb) = (w[0], w[1]);
                let (a, b) = (span.points[ka], span.points[kb]);
                let own = span.feed_caps[ka];
                let lens: Vec<f64> = (a + 1..=b)
                    .map(|j| (tp.points[j].p - tp.points[j - 1].p).norm())
                    .collect();
                let total: f64 = lens.iter().sum();
                let mut before = 0.0;
                for (j, len) in (a + 1..=b).zip(&lens) {
                    if *len <= 0.0 {
                        continue;
                    }
                    let pieces = self.moves.get(j).map_or(&[][..], |v| &v[..]);
                    let list: Vec<FeedPiece> = if pieces.is_empty() {
                        vec![FeedPiece { t: 0.0, cap: None }]
                    } else {
                        pieces.to_vec()
                    };
                    for piece in list {
                        let frac = (before + piece.t * len) / total;
                        let u = knots[ka] + frac * (knots[kb] - knots[ka]);
                        let (cap, by) = match piece.cap {
                            Some((c, lim)) if c < fmax => (c, Some(lim)),
                            Some(_) => (fmax, None),
                            None => (own, None),
                        };
                        // A piece at the same u replaces the previous one; equal caps merge.
                        if pc.u.last() == Some(&u) {
                            pc.u.pop();
                            pc.cap.pop();
                            pc.by.pop();
                        }
                        if pc.cap.last() == Some(&cap) && pc.by.last() == Some(&by) {
                            continue;
                        }
                        pc.u.push(if pc.u.is_empty() { 0.0 } else { u });
                        pc.cap.push(cap);
                        pc.by.push(by);
                    }
                    before += len;
                }
            }
            span.process = Some(pc);
        }
        Ok(())
    }
}

/// A tool object (`{"diameter", "corner_radius", "flute_length", "flutes"}`, each optional)
/// at `field` of `source`: the machine file's `tool`, or an entry of a JSON tool table.
pub fn tool_spec_from_json(source: &Path, field: &str, v: &serde_json::Value) -> Result<ToolSpec> {
    let err = |f: &str, m: String| Error::field(source, format!("{field}{f}"), m);
    let obj = v
        .as_object()
        .ok_or_else(|| err("", "expected a JSON object".into()))?;
    const KEYS: [&str; 4] = ["diameter", "corner_radius", "flute_length", "flutes"];
    if let Some(k) = obj.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return Err(err(
            &format!(".{k}"),
            format!("unknown field (expected one of: {})", KEYS.join(", ")),
        ));
    }
    // `any`: the corner radius, any finite number (Tool::new says what is wrong with it).
    let num = |key: &str, max: f64, any: bool| -> Result<Option<f64>> {
        obj.get(key)
            .map(|v| {
                let x = v.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                    err(
                        &format!(".{key}"),
                        format!("expected a finite number, found {v}"),
                    )
                })?;
                if any || (x > 0.0 && x <= max) {
                    Ok(x)
                } else {
                    Err(err(
                        &format!(".{key}"),
                        format!("must be positive and at most {max:e}, found {x}"),
                    ))
                }
            })
            .transpose()
    };
    Ok(ToolSpec {
        diameter: num("diameter", tool::MAX_TOOL_DIAMETER_MM, false)?,
        corner_radius: num("corner_radius", f64::INFINITY, true)?,
        flute_length: num("flute_length", 1e5, false)?,
        flutes: obj
            .get("flutes")
            .map(|v| {
                v.as_u64()
                    .filter(|&n| (1..=64).contains(&n))
                    .map(|n| n as u32)
                    .ok_or_else(|| err(".flutes", format!("expected 1 to 64, found {v}")))
            })
            .transpose()?,
    })
}

/// Reads the `stock`, `tool` and `process` sections of a machine file (each optional;
/// `None` when the file has no `stock`). Errors name the field.
pub fn from_machine_file(path: &Path) -> Result<Option<MaterialSpec>> {
    let bytes =
        crate::files::read_bounded(path, crate::files::MAX_MACHINE_FILE_BYTES, "machine file")?;
    let text = crate::files::utf8(path, bytes)?;
    MaterialSpec::from_json(path, &text)
}

/// The material sections of a machine file, before options and the program fill the gaps
/// (spindle speed, tool).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MaterialSpec {
    /// The `stock` section, if any.
    pub stock: Option<Stock>,
    /// Diameter, corner radius, flute length, flutes, as far as given.
    pub tool: ToolSpec,
    /// The `tools` section: a tool table inline, or the name of a tool table file (relative
    /// to the machine file; [`tooltable`]).
    pub tools: Option<tooltable::ToolTable>,
    /// The `process` section (every limit optional).
    pub process: ProcessLimits,
}

/// A tool as far as the machine file, the options or the program give it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ToolSpec {
    /// Diameter, mm.
    pub diameter: Option<f64>,
    /// Corner radius, mm (0: flat; half the diameter: ball).
    pub corner_radius: Option<f64>,
    /// Flute length, mm.
    pub flute_length: Option<f64>,
    /// Number of flutes.
    pub flutes: Option<u32>,
}

impl ToolSpec {
    /// `self` where given, else `other`.
    pub fn or(self, other: ToolSpec) -> ToolSpec {
        ToolSpec {
            diameter: self.diameter.or(other.diameter),
            corner_radius: self.corner_radius.or(other.corner_radius),
            flute_length: self.flute_length.or(other.flute_length),
            flutes: self.flutes.or(other.flutes),
        }
    }

    /// The tool: the diameter is required; corner radius 0, flute length 2 D and 2 flutes when
    /// not given (the flutes matter only to the chip load, which then requires them).
    pub fn build(&self, needs_flutes: bool) -> std::result::Result<Tool, String> {
        let d = self.diameter.ok_or(
            "no tool diameter: give the machine file's `tool.diameter`, --tool-diameter, a \
                 CUTTER/ record or the tool table's D",
        )?;
        if needs_flutes && self.flutes.is_none() {
            return Err(
                "the chip load needs the tool's flutes: give `tool.flutes`, --tool-flutes or \
                 the JSON tool table's `flutes`"
                    .into(),
            );
        }
        Tool::new(
            d,
            self.corner_radius.unwrap_or(0.0),
            self.flute_length.unwrap_or(2.0 * d),
            self.flutes.unwrap_or(2),
        )
    }
}

impl MaterialSpec {
    /// Parses the sections from machine-file JSON (`source` names the file).
    pub fn from_json(source: &Path, text: &str) -> Result<Option<MaterialSpec>> {
        use serde_json::Value;
        let value: Value = serde_json::from_str(text).map_err(|e| Error::Parse {
            file: source.to_path_buf(),
            line: e.line(),
            message: format!("invalid JSON: {e}"),
        })?;
        let err = |field: &str, m: String| Error::field(source, field, m);
        let known = |obj: &serde_json::Map<String, Value>, field: &str, keys: &[&str]| {
            for k in obj.keys() {
                if !keys.contains(&k.as_str()) {
                    return Err(err(
                        &format!("{field}.{k}"),
                        format!("unknown field (expected one of: {})", keys.join(", ")),
                    ));
                }
            }
            Ok(())
        };
        let num = |v: &Value, field: &str| -> Result<f64> {
            v.as_f64()
                .filter(|x| x.is_finite())
                .ok_or_else(|| err(field, format!("expected a finite number, found {v}")))
        };
        let positive = |obj: &serde_json::Map<String, Value>, key: &str, field: &str, max: f64| {
            obj.get(key)
                .map(|v| {
                    let x = num(v, &format!("{field}.{key}"))?;
                    if x > 0.0 && x <= max {
                        Ok(x)
                    } else {
                        Err(err(
                            &format!("{field}.{key}"),
                            format!("must be positive and at most {max:e}, found {x}"),
                        ))
                    }
                })
                .transpose()
        };
        let nums = |v: &Value, field: &str, n: usize| -> Result<Vec<f64>> {
            let items = v
                .as_array()
                .filter(|a| a.len() == n)
                .ok_or_else(|| err(field, format!("expected a list of {n} numbers (mm)")))?;
            items.iter().map(|x| num(x, field)).collect()
        };
        let Some(root) = value.as_object() else {
            return Ok(None);
        };
        let mut spec = MaterialSpec::default();
        if let Some(s) = root.get("stock") {
            let obj = s
                .as_object()
                .ok_or_else(|| err("stock", "expected a JSON object".into()))?;
            known(obj, "stock", &["box", "cylinder"])?;
            let stock = match (obj.get("box"), obj.get("cylinder")) {
                (Some(b), None) => {
                    let b = b
                        .as_object()
                        .ok_or_else(|| err("stock.box", "expected a JSON object".into()))?;
                    known(b, "stock.box", &["min", "max"])?;
                    let min = nums(b.get("min").unwrap_or(&Value::Null), "stock.box.min", 3)?;
                    let max = nums(b.get("max").unwrap_or(&Value::Null), "stock.box.max", 3)?;
                    Stock::Box {
                        min: [min[0], min[1], min[2]],
                        max: [max[0], max[1], max[2]],
                    }
                }
                (None, Some(c)) => {
                    let c = c
                        .as_object()
                        .ok_or_else(|| err("stock.cylinder", "expected a JSON object".into()))?;
                    known(c, "stock.cylinder", &["center", "radius", "z"])?;
                    let center = nums(
                        c.get("center").unwrap_or(&Value::Null),
                        "stock.cylinder.center",
                        2,
                    )?;
                    let z = nums(c.get("z").unwrap_or(&Value::Null), "stock.cylinder.z", 2)?;
                    let radius = positive(c, "radius", "stock.cylinder", 1e6)?
                        .ok_or_else(|| err("stock.cylinder.radius", "missing".into()))?;
                    Stock::Cylinder {
                        center: [center[0], center[1]],
                        radius,
                        z: [z[0], z[1]],
                    }
                }
                _ => {
                    return Err(err(
                        "stock",
                        "give exactly one of `box` {min, max} or `cylinder` {center, radius, z}"
                            .into(),
                    ));
                }
            };
            stock.validate().map_err(|e| err("stock", e))?;
            spec.stock = Some(stock);
        }
        if let Some(t) = root.get("tool") {
            spec.tool = tool_spec_from_json(source, "tool", t)?;
        }
        if let Some(t) = root.get("tools") {
            spec.tools = Some(match t {
                // A file of its own, relative to the machine file.
                Value::String(name) => {
                    let path = source.parent().unwrap_or(Path::new("")).join(name);
                    tooltable::read(&path)?
                }
                _ => tooltable::from_json(source, "tools", t)?,
            });
        }
        if let Some(p) = root.get("process") {
            let obj = p
                .as_object()
                .ok_or_else(|| err("process", "expected a JSON object".into()))?;
            known(
                obj,
                "process",
                &[
                    "chip_load",
                    "spindle_speed",
                    "mrr_max",
                    "power",
                    "kc",
                    "air_feed",
                ],
            )?;
            let pr = &mut spec.process;
            pr.chip_load = positive(obj, "chip_load", "process", 100.0)?;
            pr.spindle_speed = positive(obj, "spindle_speed", "process", 1e6)?;
            pr.mrr_max = positive(obj, "mrr_max", "process", 1e12)?;
            pr.power = positive(obj, "power", "process", 1e9)?;
            pr.kc = positive(obj, "kc", "process", 1e6)?;
            pr.air_feed = positive(obj, "air_feed", "process", 1e9)?;
            if pr.power.is_some() != pr.kc.is_some() {
                return Err(err(
                    "process.power",
                    "the power limit needs both `power` (W) and `kc` (N/mm²)".into(),
                ));
            }
        }
        Ok((spec.stock.is_some()
            || spec.process.any()
            || spec.tool.diameter.is_some()
            || spec.tools.is_some())
        .then_some(spec))
    }
}

/// Where the material model's inputs come from besides the machine file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Overrides {
    /// The tool as the options give it (first choice, for every tool of the program).
    pub tool: ToolSpec,
    /// The tool table the options give (`--tool-table`; instead of the machine file's
    /// `tools`).
    pub tool_table: Option<tooltable::ToolTable>,
    /// The spindle speed option, rpm (first choice).
    pub spindle_speed: Option<f64>,
    /// Resolution.
    pub options: CutOptions,
}

impl Material {
    /// The material model of a run: the machine file's sections (`spec`, `None` without any),
    /// the program's tools and spindle speed (`program`), and the options (`o`). Field by
    /// field, the options win over the program's tool (its `CUTTER/`, or the tool table's
    /// entry for its `T` number or name), which wins over the machine file's `tool`. Every
    /// tool the program selects becomes a [`ToolUse`] from its first move on; the moves before
    /// the first selection are cut with the first tool. Without a tool table, one tool number
    /// or name all through stands for the machine file's or the options' tool, and two are
    /// an error asking for a table. `None` when there is no stock; an
    /// error naming what is missing when process limits are given without a stock, a tool or
    /// the spindle speed the chip load needs, and naming the program line where a selected
    /// tool is not in the tool table.
    pub fn resolve(
        file: &Path,
        spec: Option<MaterialSpec>,
        program: &program::ProgramProcess,
        o: &Overrides,
    ) -> Result<Option<Material>> {
        let spec = spec.unwrap_or_default();
        let field = |f: &str, m: String| Error::field(file, f, m);
        let Some(stock) = spec.stock else {
            if spec.process.any() {
                return Err(field(
                    "stock",
                    "process limits need a stock: add `stock` {\"box\": {\"min\": [x, y, z], \
                     \"max\": [x, y, z]}} or {\"cylinder\": …}"
                        .into(),
                ));
            }
            return Ok(None);
        };
        let mut process = spec.process;
        let needs_flutes = process.chip_load.is_some();
        let build =
            |from_program: ToolSpec| o.tool.or(from_program).or(spec.tool).build(needs_flutes);
        let table = o.tool_table.as_ref().or(spec.tools.as_ref());
        let mut tools: Vec<ToolUse> = Vec::new();
        for change in &program.tool_changes {
            if change.point >= program.points.max(1) && !tools.is_empty() {
                // After the last move (an unload, `T0 M6`): it cuts nothing.
                continue;
            }
            let sel = &change.tool;
            let at = |m: String| Error::parse(&program.source, change.line, m);
            if table.is_none() && !matches!(sel, ToolSelect::Cutter { .. }) {
                // No table: one tool number all through is the machine file's or the options'
                // tool (as a program with `T1 M6` was read before tool tables); two are an error.
                let first = program
                    .tool_changes
                    .iter()
                    .find(|c| !matches!(c.tool, ToolSelect::Cutter { .. }));
                if let Some(first) = first.filter(|f| f.tool != *sel) {
                    return Err(at(format!(
                        "{sel}: the program changes tools ({} at line {}): give a tool table \
                         (--tool-table FILE, or the machine file's `tools`) so that the material \
                         model knows each",
                        first.tool, first.line
                    )));
                }
                continue;
            }
            let given = match sel {
                ToolSelect::Cutter {
                    diameter,
                    corner_radius,
                } => ToolSpec {
                    diameter: Some(*diameter),
                    corner_radius: Some(*corner_radius),
                    ..ToolSpec::default()
                },
                ToolSelect::Number(_) | ToolSelect::Name(_) => {
                    let Some(table) = table else {
                        return Err(at(format!(
                            "{sel} selects a tool the material model needs to know: give a \
                             tool table (--tool-table FILE, or the machine file's `tools`)"
                        )));
                    };
                    let Some(entry) = table.lookup(sel) else {
                        return Err(at(format!(
                            "{sel}: the tool table {} has no tool {}: add it to the table or \
                             correct the program",
                            table.source.display(),
                            match sel {
                                ToolSelect::Name(s) => format!("\"{s}\""),
                                _ => sel.to_string().trim_start_matches('T').to_string(),
                            }
                        )));
                    };
                    entry.tool
                }
            };
            let tool = build(given).map_err(|e| at(format!("{sel}: {e}")))?;
            let first_move = if tools.is_empty() { 0 } else { change.point };
            match tools.last_mut() {
                // The same tool again: no change.
                Some(last) if last.tool == tool && last.select.as_ref() == Some(sel) => {}
                // Two selections before a move: the later one cuts.
                Some(last) if last.first_move >= first_move => {
                    *last = ToolUse {
                        first_move: last.first_move,
                        line: change.line,
                        select: Some(sel.clone()),
                        tool,
                    };
                }
                _ => tools.push(ToolUse {
                    first_move,
                    line: change.line,
                    select: Some(sel.clone()),
                    tool,
                }),
            }
        }
        if tools.is_empty() {
            let tool = build(ToolSpec::default()).map_err(|e| field("tool", e))?;
            tools.push(ToolUse {
                first_move: 0,
                line: 0,
                select: None,
                tool,
            });
        }
        // The spindle speed: the option for every move; else the program's, move by move
        // (the machine file's before the program's first, or the program's first without it);
        // else the machine file's.
        let mut spindle: Vec<SpindleUse> = Vec::new();
        if let Some(n) = o.spindle_speed {
            process.spindle_speed = Some(n);
        } else {
            for c in &program.spindle_changes {
                let at = |m: String| Error::parse(&program.source, c.line, m);
                if !(c.rpm.is_finite() && c.rpm > 0.0 && c.rpm <= 1e6) {
                    return Err(at(format!(
                        "S {}: a spindle speed is from 0 to 1e6 rpm",
                        c.rpm
                    )));
                }
                let first_move = c.point;
                match spindle.last_mut() {
                    // Two speeds before a move: the later one runs it.
                    Some(last) if last.first_move >= first_move => {
                        *last = SpindleUse {
                            first_move,
                            line: c.line,
                            rpm: c.rpm,
                        }
                    }
                    _ => spindle.push(SpindleUse {
                        first_move,
                        line: c.line,
                        rpm: c.rpm,
                    }),
                }
            }
            if process.spindle_speed.is_none() {
                process.spindle_speed = spindle.first().map(|s| s.rpm);
            }
        }
        if let Some(n) = process.spindle_speed {
            if !(n.is_finite() && n > 0.0 && n <= 1e6) {
                return Err(Error::Usage(format!(
                    "spindle speed {n} rpm: give a speed from 0 to 1e6 rpm"
                )));
            }
        }
        if process.chip_load.is_some() && process.spindle_speed.is_none() {
            return Err(field(
                "process.spindle_speed",
                "the chip load needs the spindle speed: program S / SPINDL/, give \
                 `process.spindle_speed` or --spindle-speed"
                    .into(),
            ));
        }
        Ok(Some(Material {
            stock,
            tools,
            process,
            spindle,
            options: o.options,
        }))
    }
}

/// What a person reads about the material model after a run (`--json`: the `material`
/// object).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MaterialReport {
    /// The blank.
    pub stock: Stock,
    /// The cutter used (the first, where the program changes tools).
    pub tool: Tool,
    /// Flat, ball or bull-nose, from the corner radius.
    pub tool_kind: tool::ToolKind,
    /// Every tool in the order the program uses it, with where it starts and what it cut.
    pub tools: Vec<ToolReport>,
    /// The process limits applied.
    pub process: ProcessLimits,
    /// Dexel cells along X and Y.
    pub dexels: [usize; 2],
    /// Cell size along X and Y, mm.
    pub cell_mm: [f64; 2],
    /// Sample step along the path, mm.
    pub sample_step_mm: f64,
    /// Path samples cut.
    pub samples: usize,
    /// Stock volume before the program, mm³.
    pub initial_volume_mm3: f64,
    /// Volume removed by the samples, mm³.
    pub removed_volume_mm3: f64,
    /// Stock volume after the program, mm³.
    pub final_volume_mm3: f64,
    /// Largest engaged cross-section A over the samples, mm².
    pub peak_area_mm2: f64,
    /// Largest axial depth of cut a_p, mm.
    pub peak_axial_depth_mm: f64,
    /// Largest radial engagement a_e, mm.
    pub peak_radial_engagement_mm: f64,
    /// Share of the path length (samples) cutting air.
    pub air_share: f64,
    /// Dexel updates done.
    pub work: f64,
    /// How many different spindle speeds the program sets (each move's chip load uses the
    /// one in force there).
    pub program_spindle_speeds: usize,
    /// The program's spindle speeds from their first moves on (empty: `process.spindle_speed`
    /// for every move).
    pub spindle: Vec<SpindleUse>,
    /// The overload check's findings.
    pub findings: Vec<check::Finding>,
}

/// What one tool of the program did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ToolReport {
    /// What the program writes (`T2`, `CUTTER/10,2`; `null`: no selection, the machine file's
    /// or the options' tool).
    pub select: Option<String>,
    /// The program line that selects it (0: none).
    pub line: usize,
    /// The source line of its first move (0: it moves nowhere).
    pub first_move_line: usize,
    /// The tool.
    pub tool: Tool,
    /// Flat, ball or bull-nose.
    pub kind: tool::ToolKind,
    /// The sample step of its moves, mm.
    pub sample_step_mm: f64,
    /// Path samples it cut.
    pub samples: usize,
    /// Volume it removed, mm³.
    pub removed_volume_mm3: f64,
    /// Largest engaged cross-section A of its samples, mm².
    pub peak_area_mm2: f64,
}

impl MaterialReport {
    /// The report of `sim` under `m`.
    pub fn new(
        m: &Material,
        sim: &Simulation,
        program: &program::ProgramProcess,
        findings: Vec<check::Finding>,
    ) -> MaterialReport {
        let peak = |f: fn(&Sample) -> f64| sim.samples.iter().map(f).fold(0.0, f64::max);
        let total: f64 = sim.samples.iter().map(|s| s.length).sum();
        let air: f64 = sim
            .samples
            .iter()
            .filter(|s| s.removed <= 0.0)
            .map(|s| s.length)
            .sum();
        let tools = m
            .tools
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let mine: Vec<&Sample> = sim
                    .samples
                    .iter()
                    .filter(|s| m.tool_index(s.point) == i)
                    .collect();
                ToolReport {
                    select: t.select.as_ref().map(ToString::to_string),
                    line: t.line,
                    first_move_line: mine.first().map_or(0, |s| s.line),
                    tool: t.tool,
                    kind: t.tool.kind(),
                    sample_step_mm: m.step_for(&t.tool),
                    samples: mine.len(),
                    removed_volume_mm3: mine.iter().map(|s| s.removed).sum(),
                    peak_area_mm2: mine.iter().map(|s| s.area).fold(0.0, f64::max),
                }
            })
            .collect();
        MaterialReport {
            stock: m.stock,
            tool: *m.tool(),
            tool_kind: m.tool().kind(),
            tools,
            process: m.process,
            dexels: [sim.dexels.nx, sim.dexels.ny],
            cell_mm: [sim.cell.0, sim.cell.1],
            sample_step_mm: sim.step,
            samples: sim.samples.len(),
            initial_volume_mm3: sim.initial_volume,
            removed_volume_mm3: sim.removed_volume,
            final_volume_mm3: sim.final_volume,
            peak_area_mm2: peak(|s| s.area),
            peak_axial_depth_mm: peak(|s| s.axial_depth),
            peak_radial_engagement_mm: peak(|s| s.radial_engagement),
            air_share: if total > 0.0 { air / total } else { 0.0 },
            work: sim.work,
            program_spindle_speeds: program.spindle_speeds(),
            spindle: m.spindle.clone(),
            findings,
        }
    }
}

/// A tool's dimension for the report, mm: to 0.1 µm, without trailing zeros (a table's
/// `1.5 * 25.4` flutes are 38.1 mm, not 38.099999999999994).
fn mm(x: f64) -> String {
    crate::base::trimmed(x, 4)
}

impl std::fmt::Display for MaterialReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.tools.len() > 1 {
            for (i, u) in self.tools.iter().enumerate() {
                let t = &u.tool;
                writeln!(
                    f,
                    "tool {:<8} {} at line {}: {:?} end mill D {} mm, r {} mm, {} flutes, flute \
                     length {} mm; first move line {}, removed {:.1} mm³, peak A {:.3} mm²",
                    format!("{}/{}", i + 1, self.tools.len()),
                    u.select.as_deref().unwrap_or("(no selection)"),
                    u.line,
                    u.kind,
                    mm(t.diameter),
                    mm(t.corner_radius),
                    t.flutes,
                    mm(t.flute_length),
                    u.first_move_line,
                    u.removed_volume_mm3,
                    u.peak_area_mm2
                )?;
            }
        } else {
            let t = &self.tool;
            writeln!(
                f,
                "tool          {:?} end mill D {} mm, r {} mm, {} flutes, flute length {} mm",
                self.tool_kind,
                mm(t.diameter),
                mm(t.corner_radius),
                t.flutes,
                mm(t.flute_length)
            )?;
        }
        writeln!(
            f,
            "stock         {:.1} mm³ → removed {:.1} mm³ → {:.1} mm³ ({}×{} dexels of {:.3} mm, \
             {} samples of {:.3} mm, {:.1} % in air)",
            self.initial_volume_mm3,
            self.removed_volume_mm3,
            self.final_volume_mm3,
            self.dexels[0],
            self.dexels[1],
            self.cell_mm[0],
            self.samples,
            self.sample_step_mm,
            100.0 * self.air_share
        )?;
        writeln!(
            f,
            "engagement    peak A {:.3} mm², a_p {:.3} mm, a_e {:.3} mm",
            self.peak_area_mm2, self.peak_axial_depth_mm, self.peak_radial_engagement_mm
        )?;
        let (lo, hi) = self
            .spindle
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), s| {
                (lo.min(s.rpm), hi.max(s.rpm))
            });
        if self.spindle.len() > 1 && lo < hi {
            writeln!(
                f,
                "spindle       {lo}–{hi} rpm: the program's {} speeds, each on its moves",
                self.program_spindle_speeds
            )?;
        } else if let Some(n) = self
            .spindle
            .first()
            .map(|s| s.rpm)
            .or(self.process.spindle_speed)
        {
            writeln!(f, "spindle       {n} rpm")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod report_tests {
    #[test]
    fn a_tools_dimensions_are_reported_without_rounding_noise() {
        assert_eq!(super::mm(1.5 * 25.4), "38.1");
        assert_eq!(super::mm(6.0), "6");
        assert_eq!(super::mm(3.175), "3.175");
        assert_eq!(super::mm(0.0), "0");
    }
}
