//! Plots of a schedule (SVG, drawn with `plotters`): where and why the machine slows down.
//!
//! [`write_solution_plot`] draws three stacked panels:
//!
//! 1. the feed V against the path length s, coloured by the limit that holds it down in each
//!    interval ([`crate::report::interval_binding`], the same rule as the summary's shares),
//!    with the limits it runs against: the maximum-velocity curve |P'|·√b_max (every velocity
//!    limit, the feed cap and the acceleration-limited curvature bound at each station), the
//!    feed cap, and each axis's velocity bound |P'|·v_q / |q'| (the V at which that axis alone
//!    reaches its velocity limit);
//! 2. each axis's |q̇| / v_q against time;
//! 3. each axis's |q̈| / a_q against time (both ends of every interval, with its ü).
//!
//! [`write_profiles_plot`] draws several feed profiles against s in one panel (`feedopt
//! compare --plot`).
//!
//! Only SVG is written: PNG needs a font rasteriser with font files, which feedopt does not
//! bundle (`rsvg-convert plot.svg -o plot.png` converts). Long schedules are thinned to the
//! minimum and maximum of each of about two thousand bins along the horizontal axis, so the
//! envelope is drawn exactly and the file stays small.

use std::path::Path;

use plotters::prelude::*;

use crate::constraints::Bound;
use crate::error::{Error, Result};
use crate::geometry::SpanKind;
use crate::machine::Machine;
use crate::optimize::Solution;
use crate::report::{binding_label, interval_binding};
use crate::schedule::Schedule;

/// Bins along the horizontal axis beyond which a series is thinned.
const BINS: usize = 2000;
const WIDTH: u32 = 1400;
const FONT: &str = "sans-serif";

/// Distinct colours: black for the feed, then one per axis limit.
const PALETTE: [RGBColor; 12] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(127, 127, 127),
    RGBColor(0, 0, 128),
    RGBColor(128, 0, 0),
];

/// Colour of axis `j` (its velocity curves and its velocity binding).
fn axis_colour(j: usize) -> RGBColor {
    PALETTE[j % PALETTE.len()]
}

/// Colour of a binding limit: the axis's colour for its velocity, a darker shade for its
/// acceleration, teal for the feed, light grey where nothing binds.
fn bound_colour(b: Bound) -> RGBColor {
    match b {
        Bound::Feed => RGBColor(0, 150, 136),
        Bound::AxisVelocity(j) => axis_colour(j),
        Bound::AxisAcceleration(j) => {
            let RGBColor(r, g, b) = axis_colour(j);
            RGBColor(r / 2, g / 2, b / 2)
        }
        Bound::AxisJerk(j) => {
            let RGBColor(r, g, b) = axis_colour(j);
            RGBColor(r / 2 + 127, g / 2 + 127, b / 2 + 127)
        }
        Bound::Chord => RGBColor(156, 39, 176),
        Bound::Process(l) => match l {
            crate::material::ProcessLimit::ChipLoad => RGBColor(121, 85, 72),
            crate::material::ProcessLimit::Mrr => RGBColor(233, 30, 99),
            crate::material::ProcessLimit::Power => RGBColor(255, 152, 0),
            crate::material::ProcessLimit::Air => RGBColor(3, 169, 244),
        },
        Bound::None => RGBColor(170, 170, 170),
    }
}

fn draw_err(path: &Path) -> impl Fn(String) -> Error + '_ {
    move |e| {
        Error::io(
            path,
            std::io::Error::other(format!("drawing the plot: {e}")),
        )
    }
}

/// Thins a series to the first, minimum, maximum and last point of each of `BINS` bins of
/// x (in order), so its envelope is kept. Short series are returned as they are.
pub fn thin(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let (Some(first), Some(last)) = (points.first(), points.last()) else {
        return Vec::new();
    };
    let mut t = Thinner::new(first.0, last.0);
    for &p in points {
        t.push(p);
    }
    t.finish()
}

/// A series thinned as it is built ([`thin`]'s points, without holding every point of a long
/// series): the points themselves while there are at most 2·`BINS`, else, per bin of x over a
/// range given up front, the bin's first, lowest, highest and last point, in order.
struct Thinner {
    x0: f64,
    width: f64,
    /// The points so far, while there are at most 2·`BINS`.
    raw: Vec<(f64, f64)>,
    count: usize,
    /// The bins closed so far, thinned.
    out: Vec<(f64, f64)>,
    bin: Option<Bin>,
    /// The largest finite y pushed.
    peak: f64,
}

impl Thinner {
    /// For a series whose x run from `x0` to `x1`.
    fn new(x0: f64, x1: f64) -> Thinner {
        Thinner {
            x0,
            width: (x1 - x0).max(f64::MIN_POSITIVE),
            raw: Vec::new(),
            count: 0,
            out: Vec::new(),
            bin: None,
            peak: f64::NEG_INFINITY,
        }
    }

    fn bin_of(&self, x: f64) -> usize {
        (((x - self.x0) / self.width * BINS as f64) as usize).min(BINS - 1)
    }

    fn push(&mut self, p: (f64, f64)) {
        self.count += 1;
        if self.count <= 2 * BINS {
            self.raw.push(p);
        } else if self.count == 2 * BINS + 1 {
            self.raw = Vec::new();
        }
        if p.1.is_finite() {
            self.peak = self.peak.max(p.1);
        }
        let b = self.bin_of(p.0);
        match &mut self.bin {
            Some(bin) if bin.index == b => bin.add(p),
            _ => {
                if let Some(done) = self.bin.replace(Bin::new(b, p)) {
                    done.thinned(&mut self.out);
                }
            }
        }
    }

    /// The thinned series.
    fn finish(mut self) -> Vec<(f64, f64)> {
        if self.count <= 2 * BINS {
            return self.raw;
        }
        if let Some(done) = self.bin.take() {
            done.thinned(&mut self.out);
        }
        self.out
    }
}

/// One bin of a [`Thinner`]: its first, lowest, highest and last point, each with its place.
#[derive(Debug, Clone, Copy)]
struct Bin {
    index: usize,
    n: usize,
    first: (usize, (f64, f64)),
    lo: (usize, (f64, f64)),
    hi: (usize, (f64, f64)),
    last: (usize, (f64, f64)),
}

impl Bin {
    fn new(index: usize, p: (f64, f64)) -> Bin {
        Bin {
            index,
            n: 1,
            first: (0, p),
            lo: (0, p),
            hi: (0, p),
            last: (0, p),
        }
    }

    fn add(&mut self, p: (f64, f64)) {
        let k = self.n;
        self.n += 1;
        if p.1 < self.lo.1.1 {
            self.lo = (k, p);
        }
        if p.1 > self.hi.1.1 {
            self.hi = (k, p);
        }
        self.last = (k, p);
    }

    /// Appends the bin's points, in order, each once.
    fn thinned(&self, out: &mut Vec<(f64, f64)>) {
        let mut keep = [self.first, self.lo, self.hi, self.last];
        keep.sort_unstable_by_key(|k| k.0);
        let mut last = usize::MAX;
        for (k, p) in keep {
            if k != last {
                out.push(p);
                last = k;
            }
        }
    }
}

/// Splits a series into runs of finite points at most `y_max` (a bound that leaves the chart
/// is drawn where it is inside it).
fn runs_below(points: &[(f64, f64)], y_max: f64) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for &(x, y) in points {
        if y.is_finite() && y <= y_max {
            cur.push((x, y));
        } else if !cur.is_empty() {
            runs.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        runs.push(cur);
    }
    runs
}

/// Axis labels of a path: tool-tip length and feed, or a joint-space path's parameter.
fn path_labels(joint_space: bool) -> (&'static str, &'static str) {
    if joint_space {
        ("path parameter s (as in the CSV)", "path speed ds/dt (1/s)")
    } else {
        ("tool-tip path length s (mm)", "feed V (mm/s)")
    }
}

/// Writes the three-panel plot of a solution (see the module documentation) to `path` (.svg),
/// atomically.
/// `name` names the toolpath in the title.
pub fn write_solution_plot(
    path: &Path,
    name: &str,
    machine: &Machine,
    solution: &Solution,
) -> Result<()> {
    super::output_format(path, super::PLOT)?;
    let mut svg = String::new();
    draw_solution(&mut svg, name, machine, solution).map_err(draw_err(path))?;
    super::write_atomically(path, svg.as_bytes())
}

/// Panel 1's series, each thinned as it is built.
struct FeedData {
    /// The feed as polylines of one binding limit each ([`ColouredRuns`]).
    runs: Vec<(Bound, Vec<(f64, f64)>)>,
    mvc: Vec<(f64, f64)>,
    cap: Vec<(f64, f64)>,
    /// The largest finite feed cap.
    cap_peak: f64,
    axis_bounds: Vec<Vec<(f64, f64)>>,
}

fn feed_data(machine: &Machine, solution: &Solution, s_max: f64) -> FeedData {
    let na = solution.kinematics.n_axes().min(machine.axes.len());
    let st = &solution.schedule.stations;
    let mut runs = ColouredRuns::new(s_max);
    let mut mvc = Thinner::new(0.0, s_max);
    let mut cap = Thinner::new(0.0, s_max);
    let mut axis_bounds: Vec<Thinner> = (0..na).map(|_| Thinner::new(0.0, s_max)).collect();
    let mut offset = 0;
    for ((p, sol), span) in solution
        .problems
        .iter()
        .zip(&solution.solutions)
        .zip(&solution.path.spans)
    {
        let joint = span.kind == SpanKind::Joint;
        // V per unit u̇: |P'| on a moving span, 1 on a joint path (a reorientation has none).
        let scale = |i: usize| if joint { 1.0 } else { p.tip_speed[i] };
        for i in 0..p.u.len() {
            let s = st[offset + i].s;
            if span.kind == SpanKind::Reorientation {
                continue;
            }
            mvc.push((s, scale(i) * p.b_max[i].sqrt()));
            for (j, bounds) in axis_bounds.iter_mut().enumerate() {
                let dq = p.jets.dq(i)[j];
                let axis = &machine.axes[j];
                let v = if dq >= 0.0 {
                    axis.velocity.max
                } else {
                    -axis.velocity.min
                };
                bounds.push((s, scale(i) * v / dq.abs()));
            }
        }
        let jerk = crate::report::jerk_ratios(machine, span, &solution.kinematics, p, sol);
        for k in 0..p.intervals() {
            let (a, z) = (&st[offset + k], &st[offset + k + 1]);
            runs.push(
                (a.s, a.v),
                (z.s, z.v),
                interval_binding(p, sol, k, jerk.as_deref()),
            );
            if !joint && span.kind == SpanKind::Moving {
                let c = span.feed_caps[span.spline.segment(0.5 * (p.u[k] + p.u[k + 1]))];
                cap.push((a.s, c));
                cap.push((z.s, c));
            }
        }
        offset += p.u.len();
    }
    FeedData {
        runs: runs.finish(),
        mvc: mvc.finish(),
        cap_peak: cap.peak.max(0.0),
        cap: cap.finish(),
        axis_bounds: axis_bounds.into_iter().map(Thinner::finish).collect(),
    }
}

fn draw_solution(
    svg: &mut String,
    name: &str,
    machine: &Machine,
    solution: &Solution,
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    let names: Vec<&str> = machine.axes.iter().map(|a| a.name.as_str()).collect();
    let joint = solution
        .path
        .spans
        .iter()
        .any(|s| s.kind == SpanKind::Joint);
    let (s_label, v_label) = path_labels(joint);
    let st = &solution.schedule.stations;
    let s_max = st.last().map_or(1.0, |s| s.s).max(1e-9);
    let data = feed_data(machine, solution, s_max);
    let v_peak = st.iter().map(|s| s.v).fold(0.0, f64::max);
    let cap_peak = data.cap_peak;
    // Headroom above the feed for the legend and the limits the feed runs up against.
    let y_max = (1.7 * v_peak)
        .max(1.1 * cap_peak.min(2.0 * v_peak))
        .max(1e-9);

    let root = SVGBackend::with_string(svg, (WIDTH, 1150)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let title = format!(
        "{name} on {}: cycle time {:.4} s",
        machine.name, solution.schedule.cycle_time
    );
    let root = root.titled(&title, (FONT, 22)).map_err(|x| e(&x))?;
    let (top, bottom) = root.split_vertically(560);
    let (mid, low) = bottom.split_vertically(290);

    // Panel 1: feed against s.
    let mut chart = ChartBuilder::on(&top)
        .caption(
            "feed, coloured by the limit holding it down, against the limits",
            (FONT, 17),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..s_max, 0.0..y_max)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc(s_label)
        .y_desc(v_label)
        .label_style((FONT, 14))
        .draw()
        .map_err(|x| e(&x))?;
    for (j, pts) in data.axis_bounds.iter().enumerate() {
        let style = axis_colour(j).mix(0.55).stroke_width(1);
        let mut first = true;
        for run in runs_below(pts, y_max) {
            let s = chart
                .draw_series(LineSeries::new(run, style))
                .map_err(|x| e(&x))?;
            if first {
                s.label(format!("{} velocity bound v/|{}'|", names[j], names[j]))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                first = false;
            }
        }
    }
    let mvc_style = RGBColor(200, 200, 200).stroke_width(9);
    let mut first = true;
    for run in runs_below(&data.mvc, y_max) {
        let s = chart
            .draw_series(LineSeries::new(run, mvc_style))
            .map_err(|x| e(&x))?;
        if first {
            s.label("maximum-velocity curve: velocity limits, feed cap, curvature (at ü = 0)")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], mvc_style));
            first = false;
        }
    }
    // The feed itself, one polyline per run of intervals with the same binding limit (thinned
    // per bin of s on long schedules: each bin drawn in the colour of the limit that binds
    // over most of its length).
    let mut labelled: Vec<Bound> = Vec::new();
    for (bound, pts) in data.runs {
        let style = bound_colour(bound).stroke_width(3);
        let s = chart
            .draw_series(LineSeries::new(pts, style))
            .map_err(|x| e(&x))?;
        if !labelled.contains(&bound) {
            labelled.push(bound);
            let what = if bound == Bound::None {
                "feed V: nothing binds (accelerating / braking between limits)".to_string()
            } else {
                format!("feed V held by {}", binding_label(bound, &names))
            };
            s.label(what)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        }
    }
    // The feed cap on top of the feed (dashed), so both stay visible where the feed runs at it.
    let cap_style = BLACK.stroke_width(1);
    let mut first = true;
    for run in runs_below(&data.cap, y_max) {
        let s = chart
            .draw_series(DashedLineSeries::new(run, 6, 4, cap_style))
            .map_err(|x| e(&x))?;
        if first {
            s.label("feed cap (programmed / machine maximum)")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], cap_style));
            first = false;
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 13))
        .draw()
        .map_err(|x| e(&x))?;

    // Panels 2 and 3: axis velocity and acceleration over their limits, against time.
    let t_max = solution.schedule.cycle_time.max(1e-9);
    let (vel, acc) = axis_ratios(machine, solution);
    for (area, series, what) in [
        (&mid, &vel, "|velocity| / limit"),
        (&low, &acc, "|acceleration| / limit"),
    ] {
        let peak = series
            .iter()
            .flat_map(|s| s.iter().map(|p| p.1))
            .filter(|x| x.is_finite())
            .fold(1.0, f64::max);
        let top_y = (1.1 * peak).min(3.0);
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!("every axis's {what} (1 = at its limit)"),
                (FONT, 17),
            )
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..t_max, 0.0..top_y)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("time t (s)")
            .y_desc(what)
            .label_style((FONT, 14))
            .draw()
            .map_err(|x| e(&x))?;
        // The limit first (underneath): an axis running at its limit stays visible on it.
        chart
            .draw_series(LineSeries::new(
                vec![(0.0, 1.0), (t_max, 1.0)],
                RGBColor(90, 90, 90).stroke_width(3),
            ))
            .map_err(|x| e(&x))?;
        for (j, pts) in series.iter().enumerate() {
            let style = axis_colour(j).stroke_width(2);
            for run in runs_below(pts, top_y) {
                chart
                    .draw_series(LineSeries::new(run, style))
                    .map_err(|x| e(&x))?;
            }
        }
        // The legend: one coloured axis name each, in the panel's top margin, off the data.
        let (w, _) = area.dim_in_pixel();
        let slot = 70i32;
        let x0 = w as i32 - 20 - slot * (names.len() as i32 + 1);
        area.draw(&Text::new(
            "limit ━".to_string(),
            (x0, 6),
            (FONT, 14).into_font().color(&RGBColor(90, 90, 90)),
        ))
        .map_err(|x| e(&x))?;
        for (j, name) in names.iter().enumerate() {
            area.draw(&Text::new(
                format!("━ {name}"),
                (x0 + slot * (j as i32 + 1), 6),
                (FONT, 14).into_font().color(&axis_colour(j)),
            ))
            .map_err(|x| e(&x))?;
        }
    }
    root.present().map_err(|x| e(&x))?;
    Ok(())
}

/// The feed as polylines of one binding limit each, built interval by interval. Short
/// schedules (at most 2·`BINS` intervals): runs of consecutive intervals with the same limit.
/// Long ones: per bin of s, the limit binding over most of the bin's length, and the bin's
/// thinned points.
struct ColouredRuns {
    s_max: f64,
    /// The short schedule's runs, while there are at most 2·`BINS` intervals.
    raw: Vec<(Bound, Vec<(f64, f64)>)>,
    count: usize,
    /// The long schedule's runs, of the bins closed so far.
    runs: Vec<(Bound, Vec<(f64, f64)>)>,
    /// The open bin: each limit's length in it, and its points.
    bin: Option<(Vec<(Bound, f64)>, Bin)>,
}

impl ColouredRuns {
    fn new(s_max: f64) -> ColouredRuns {
        ColouredRuns {
            s_max,
            raw: Vec::new(),
            count: 0,
            runs: Vec::new(),
            bin: None,
        }
    }

    /// The interval from (s, V) `a` to `z`, held down by `bound`.
    fn push(&mut self, a: (f64, f64), z: (f64, f64), bound: Bound) {
        self.count += 1;
        if self.count <= 2 * BINS {
            match self.raw.last_mut() {
                Some((rb, pts)) if *rb == bound => pts.push(z),
                _ => self.raw.push((bound, vec![a, z])),
            }
        } else if self.count == 2 * BINS + 1 {
            self.raw = Vec::new();
        }
        let index = ((a.0 / self.s_max * BINS as f64) as usize).min(BINS - 1);
        match &mut self.bin {
            Some((share, pts)) if pts.index == index => {
                match share.iter_mut().find(|x| x.0 == bound) {
                    Some(x) => x.1 += z.0 - a.0,
                    None => share.push((bound, z.0 - a.0)),
                }
                pts.add(z);
            }
            _ => {
                self.close();
                let mut pts = Bin::new(index, a);
                pts.add(z);
                self.bin = Some((vec![(bound, z.0 - a.0)], pts));
            }
        }
    }

    /// Closes the open bin: its points, in the colour of its dominant limit.
    fn close(&mut self) {
        let Some((share, bin)) = self.bin.take() else {
            return;
        };
        let dominant = share
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(Bound::None, |x| x.0);
        let mut pts = Vec::with_capacity(4);
        bin.thinned(&mut pts);
        match self.runs.last_mut() {
            Some((rb, run)) if *rb == dominant => run.extend(pts.into_iter().skip(1)),
            _ => self.runs.push((dominant, pts)),
        }
    }

    fn finish(mut self) -> Vec<(Bound, Vec<(f64, f64)>)> {
        if self.count <= 2 * BINS {
            return self.raw;
        }
        self.close();
        self.runs
    }
}

/// Per axis, (t, |q̇|/v) at every station and (t, |q̈|/a) at both ends of every interval with
/// its ü, each thinned as it is built.
#[allow(clippy::type_complexity)]
fn axis_ratios(
    machine: &Machine,
    solution: &Solution,
) -> (Vec<Vec<(f64, f64)>>, Vec<Vec<(f64, f64)>>) {
    let na = solution.kinematics.n_axes().min(machine.axes.len());
    let st = &solution.schedule.stations;
    let t_end = st.last().map_or(1.0, |s| s.t);
    let series = || -> Vec<Thinner> { (0..na).map(|_| Thinner::new(0.0, t_end)).collect() };
    let (mut vel, mut acc) = (series(), series());
    let mut offset = 0;
    for (p, sol) in solution.problems.iter().zip(&solution.solutions) {
        for i in 0..p.u.len() {
            for (j, v) in vel.iter_mut().enumerate() {
                v.push((
                    st[offset + i].t,
                    machine.axes[j]
                        .velocity
                        .ratio(solution.schedule.qd(offset + i)[j]),
                ));
            }
        }
        for k in 0..p.intervals() {
            for e in [k, k + 1] {
                for (j, series) in acc.iter_mut().enumerate() {
                    let a = p.axis_acceleration(&sol.b, sol.ends.as_deref(), k, e, j);
                    series.push((st[offset + e].t, machine.axes[j].acceleration.ratio(a)));
                }
            }
        }
        offset += p.u.len();
    }
    let done = |v: Vec<Thinner>| v.into_iter().map(Thinner::finish).collect();
    (done(vel), done(acc))
}

/// One feed profile of [`write_profiles_plot`].
pub struct ProfileCurve<'a> {
    /// The legend's text.
    pub label: String,
    /// The schedule drawn.
    pub schedule: &'a Schedule,
}

/// Writes the feed profiles of several schedules of one path against s in one panel (.svg),
/// atomically.
pub fn write_profiles_plot(
    path: &Path,
    title: &str,
    joint_space: bool,
    curves: &[ProfileCurve],
) -> Result<()> {
    super::output_format(path, super::PLOT)?;
    let mut svg = String::new();
    draw_profiles(&mut svg, title, joint_space, curves).map_err(draw_err(path))?;
    super::write_atomically(path, svg.as_bytes())
}

fn draw_profiles(
    svg: &mut String,
    title: &str,
    joint_space: bool,
    curves: &[ProfileCurve],
) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    let (s_label, v_label) = path_labels(joint_space);
    let s_max = curves
        .iter()
        .filter_map(|c| c.schedule.stations.last().map(|s| s.s))
        .fold(1e-9, f64::max);
    let v_max = curves
        .iter()
        .flat_map(|c| c.schedule.stations.iter().map(|s| s.v))
        .fold(1e-9, f64::max);
    let root = SVGBackend::with_string(svg, (WIDTH, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, (FONT, 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..s_max, 0.0..1.15 * v_max)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc(s_label)
        .y_desc(v_label)
        .label_style((FONT, 14))
        .draw()
        .map_err(|x| e(&x))?;
    for (k, c) in curves.iter().enumerate() {
        let style = PALETTE[k % PALETTE.len()].stroke_width(2);
        let pts: Vec<(f64, f64)> = c.schedule.stations.iter().map(|s| (s.s, s.v)).collect();
        chart
            .draw_series(LineSeries::new(thin(&pts), style))
            .map_err(|x| e(&x))?
            .label(c.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 13))
        .draw()
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))?;
    Ok(())
}

impl crate::sweep::Sweep {
    /// An SVG plot (cargo feature `plot`): cycle time against the limit (top) and the sensitivity, dual and finite
    /// differences (bottom); axes labelled with units, legends.
    pub fn plot_svg(&self) -> Result<String> {
        use plotters::prelude::*;
        let fail = |e: &dyn std::fmt::Display| Error::Solver(format!("plot: {e}"));
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (900, 800)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| fail(&e))?;
            let (top, bottom) = root.split_vertically(400);
            let xs: Vec<f64> = self.points.iter().map(|p| p.limit).collect();
            let (x0, x1) = pad_range(&xs);
            let xlabel = format!("{} {} limit [{}]", self.axis, self.limit, self.unit);

            let ts: Vec<f64> = self.points.iter().map(|p| p.cycle_time_s).collect();
            let (y0, y1) = pad_range(&ts);
            let mut chart = ChartBuilder::on(&top)
                .caption(
                    format!("Cycle time against the {} {} limit", self.axis, self.limit),
                    ("sans-serif", 20),
                )
                .margin(15)
                .x_label_area_size(45)
                .y_label_area_size(80)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(|e| fail(&e))?;
            chart
                .configure_mesh()
                .x_desc(xlabel.as_str())
                .y_desc("cycle time [s]")
                .draw()
                .map_err(|e| fail(&e))?;
            chart
                .draw_series(LineSeries::new(
                    self.points.iter().map(|p| (p.limit, p.cycle_time_s)),
                    BLUE.stroke_width(2),
                ))
                .map_err(|e| fail(&e))?
                .label("cycle time T")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE.stroke_width(2)));
            chart
                .draw_series(
                    self.points
                        .iter()
                        .map(|p| Circle::new((p.limit, p.cycle_time_s), 3, BLUE.filled())),
                )
                .map_err(|e| fail(&e))?;
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(|e| fail(&e))?;

            let mut ss: Vec<f64> = self.points.iter().map(|p| p.sensitivity_fd).collect();
            ss.extend(self.points.iter().filter_map(|p| p.sensitivity_dual));
            let (s0, s1) = pad_range(&ss);
            let mut chart = ChartBuilder::on(&bottom)
                .caption("Sensitivity dT/d(limit)", ("sans-serif", 20))
                .margin(15)
                .x_label_area_size(45)
                .y_label_area_size(80)
                .build_cartesian_2d(x0..x1, s0..s1)
                .map_err(|e| fail(&e))?;
            chart
                .configure_mesh()
                .x_desc(xlabel.as_str())
                .y_desc(format!("dT/d(limit) [s per {}]", self.unit))
                .y_label_formatter(&|y| {
                    // A tick at zero, not at the rounding error next to it.
                    if y.abs() < 1e-9 * (s1 - s0) {
                        "0".to_string()
                    } else {
                        format!("{y:.2e}")
                    }
                })
                .draw()
                .map_err(|e| fail(&e))?;
            if self.points.iter().any(|p| p.sensitivity_dual.is_some()) {
                chart
                    .draw_series(LineSeries::new(
                        self.points
                            .iter()
                            .filter_map(|p| p.sensitivity_dual.map(|s| (p.limit, s))),
                        RED.stroke_width(2),
                    ))
                    .map_err(|e| fail(&e))?
                    .label("from the duals")
                    .legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2))
                    });
            }
            chart
                .draw_series(
                    self.points
                        .iter()
                        .map(|p| Cross::new((p.limit, p.sensitivity_fd), 5, BLACK.stroke_width(2))),
                )
                .map_err(|e| fail(&e))?
                .label(format!("central differences (±{} %)", 100.0 * self.fd_step))
                .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .position(SeriesLabelPosition::LowerRight)
                .draw()
                .map_err(|e| fail(&e))?;
            root.present().map_err(|e| fail(&e))?;
        }
        Ok(svg)
    }

    /// Writes [`Sweep::plot_svg`](crate::sweep::Sweep::plot_svg) to `path`, atomically.
    pub fn write_plot(&self, path: &Path) -> Result<()> {
        super::write_atomically(path, self.plot_svg()?.as_bytes())
    }
}

/// A plotting range around `values` with 5 % margins (never empty).
fn pad_range(values: &[f64]) -> (f64, f64) {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.05 * lo.abs().max(1e-12)
    };
    (lo - pad, hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (s, V) at an interval's two ends, and the limit binding on it.
    type BoundInterval = ((f64, f64), (f64, f64), Bound);

    /// The feed's coloured runs of a whole schedule at once, as the plot drew them before they
    /// were built interval by interval: the reference for [`ColouredRuns`].
    fn batch_runs(intervals: &[BoundInterval], s_max: f64) -> Vec<(Bound, Vec<(f64, f64)>)> {
        let mut runs: Vec<(Bound, Vec<(f64, f64)>)> = Vec::new();
        if intervals.len() <= 2 * BINS {
            for &(a, z, b) in intervals {
                match runs.last_mut() {
                    Some((rb, pts)) if *rb == b => pts.push(z),
                    _ => runs.push((b, vec![a, z])),
                }
            }
            return runs;
        }
        let bin = |s: f64| ((s / s_max * BINS as f64) as usize).min(BINS - 1);
        let mut i = 0;
        while i < intervals.len() {
            let b0 = bin(intervals[i].0.0);
            let mut share: Vec<(Bound, f64)> = Vec::new();
            let mut pts = vec![intervals[i].0];
            while i < intervals.len() && bin(intervals[i].0.0) == b0 {
                let (a, z, b) = intervals[i];
                match share.iter_mut().find(|x| x.0 == b) {
                    Some(x) => x.1 += z.0 - a.0,
                    None => share.push((b, z.0 - a.0)),
                }
                pts.push(z);
                i += 1;
            }
            let dominant = share
                .iter()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(Bound::None, |x| x.0);
            // First, lowest, highest and last point, in order, each once.
            let (mut lo, mut hi) = (0, 0);
            for (k, p) in pts.iter().enumerate() {
                if p.1 < pts[lo].1 {
                    lo = k;
                }
                if p.1 > pts[hi].1 {
                    hi = k;
                }
            }
            let mut keep = vec![0, lo, hi, pts.len() - 1];
            keep.sort_unstable();
            keep.dedup();
            let pts: Vec<(f64, f64)> = keep.into_iter().map(|k| pts[k]).collect();
            match runs.last_mut() {
                Some((rb, run)) if *rb == dominant => run.extend(pts.into_iter().skip(1)),
                _ => runs.push((dominant, pts)),
            }
        }
        runs
    }

    /// Short and long schedules of uneven intervals, their limits changing in runs: built
    /// interval by interval, the runs are the batch reference's.
    #[test]
    fn coloured_runs_built_interval_by_interval_are_the_batch_ones() {
        let mut rnd = crate::test_rng(5);
        for n in [10, 2 * BINS, 2 * BINS + 1, 50_000] {
            let mut intervals = Vec::with_capacity(n);
            let (mut s, mut v) = (0.0, 0.0);
            let mut bound = Bound::None;
            for _ in 0..n {
                if rnd() < 0.02 {
                    bound = [Bound::None, Bound::Feed, Bound::AxisVelocity(1)]
                        [(3.0 * rnd()) as usize % 3];
                }
                let a = (s, v);
                s += 0.1 + rnd();
                v = (v + rnd() - 0.5).abs();
                intervals.push((a, (s, v), bound));
            }
            let mut built = ColouredRuns::new(s);
            for &(a, z, b) in &intervals {
                built.push(a, z, b);
            }
            assert_eq!(built.finish(), batch_runs(&intervals, s), "{n} intervals");
        }
    }
}
