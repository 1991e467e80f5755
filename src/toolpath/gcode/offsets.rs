//! Work offsets as shifts: `G54`–`G59` (and the dialects' other offsets), `G10 L2`/`L20`, the
//! local shift `G52`, and `G92`.
//!
//! # What feedopt knows of an offset
//!
//! A program's coordinates are read in the work offset it selects, whose values the control
//! holds and the program rarely gives. The toolpath is in the coordinates of the offset in
//! force when the program starts (the *start*): its points are program coordinates shifted by
//! how far the offset in force lies from the start's, where that is known. An offset's origin
//! is known, axis by axis, on one of two bases:
//!
//! * **start**: relative to the start's origin, exactly. The start itself (0); an offset set
//!   from the current position, LinuxCNC `G10 L20` (the current position becomes the given
//!   coordinates), or by an increment, Fanuc `G91 G10 L2`; and the local shift `G52` on top of
//!   any offset.
//! * **machine**: `G10 L2` (and Fanuc's `G10 L20`, its extended offsets `G54.1 P…`) gives an
//!   origin in machine coordinates. Two such origins lie exactly that far apart; from the
//!   start's, only through the machine file's work offset (where the start's origin lies in
//!   machine coordinates, the convention `G53` and `G28` use), which the program does not
//!   give.
//!
//! A point is made with the basis of the offsets in force on each axis. A move between two
//! points on different bases on an axis — after a `G10 L2` that changes the offset in force
//! once moves have been made in it, or between an offset the program set in machine
//! coordinates and one it did not — has a length that depends on values the program does not
//! give: that is an error naming the `G10` and the move. A `G10 L2` before the
//! first move (CAMotics writes `G10 L2 P1 X0 Y0 Z0` at the top), or of an offset that is not
//! used afterwards, is no error. Points in machine coordinates (`G53`, the `G28`/`G30`
//! reference point) stand outside this check: they are placed by the machine file's work
//! offset, as they always were.
//!
//! An offset the program selects without having set it is taken as equal to the one in force
//! (as before this module: the change is a warning saying so), and from then on as known on
//! that basis. An offset the program selects before its first point names the start (nothing
//! has been made in the one it replaces: a Sinumerik header's `G500`, then `G54`), unless a
//! `G10` has set the control's default (`G54`) before it. The local shift `G52` (LinuxCNC and Fanuc) applies
//! to every offset until changed; LinuxCNC's `G92.1` and `G92.2` cancel it. At the start no
//! local shift is in force (LinuxCNC can keep one from an earlier run: feedopt assumes the
//! program starts clean).
//!
//! Fanuc's external offset, `G10 L2 P0`, is added to every offset; it is tracked as one more
//! origin with its own basis.
//!
//! `G92 X…` gives the current position the coordinates named: a shift of every offset, known
//! on the start's basis like `G52`'s (LinuxCNC keeps it in `G52`'s register, so `G52` and
//! `G92.1` change it; Fanuc apart). Before the program has placed an axis, its position is the
//! unknown start, taken as 0 as everywhere: the moves after a `G92` are then exact relative to
//! the point it names, which is what a program starting with `G92 X0 Y0 Z0` means.

/// The axes X Y Z A B C.
const AXES: usize = 6;

/// Where an origin is known from (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Basis {
    /// Relative to the offset in force at the start.
    Start,
    /// In machine coordinates (through the machine file's work offset).
    Machine,
}

/// The `G10` that set an origin in machine coordinates: for messages.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Cause {
    pub(super) line: usize,
    /// The block as read (`G10 L2 P1 X100`).
    pub(super) text: String,
    /// The offset it set (`G54`, `the external offset`).
    pub(super) offset: String,
}

/// An offset's origin on one axis.
#[derive(Debug, Clone, PartialEq)]
struct Origin {
    /// Toolpath coordinates of the origin (mm, degrees); for a machine basis, its machine
    /// coordinate less the machine file's work offset.
    value: f64,
    basis: Basis,
    /// Taken as equal to another offset's origin (selected without being set).
    assumed: bool,
    /// The `G10` behind a machine basis.
    cause: Option<Cause>,
}

impl Origin {
    /// An origin a `G10` (`cause`) gives in machine coordinates.
    fn machine(value: f64, cause: &Cause) -> Origin {
        Origin {
            value,
            basis: Basis::Machine,
            assumed: false,
            cause: Some(cause.clone()),
        }
    }
}

const START: Origin = Origin {
    value: 0.0,
    basis: Basis::Start,
    assumed: false,
    cause: None,
};

/// How a `G10` sets an origin on one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Setting {
    /// `G10 L2` (and Fanuc `G10 L20`): this machine coordinate, less the machine file's work
    /// offset for a work offset (the caller's conversion).
    Machine(f64),
    /// Fanuc `G91 G10 L2`: moved by this much.
    Increment(f64),
    /// LinuxCNC `G10 L20`: the current position, `here` (toolpath coordinates), becomes
    /// `given`.
    Position { here: f64, given: f64 },
}

/// What a `G10` sets.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Target {
    /// A work offset, by name (`G55`, `G54.1 P3`).
    Offset(String),
    /// Fanuc's external offset (`G10 L2 P0`), added to every work offset.
    External,
}

/// A move whose ends are on different bases on `axis` (see the module docs): the `G10` behind
/// the machine basis, and whether the move ends on it (else it starts there).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Mismatch {
    pub(super) axis: usize,
    pub(super) cause: Option<Cause>,
    pub(super) ends_on_machine: bool,
}

/// The bases of a point on one axis (the offset in force, the external offset), and the
/// `G10` behind a machine basis.
type Key = ((Basis, Basis), Option<Cause>);

/// The offsets in force and those the program set.
#[derive(Debug, Clone)]
pub(super) struct WorkOffsets {
    /// The offset in force, and its index in `table`.
    active: String,
    active_k: usize,
    /// The program has selected none yet: `active` is the control's default.
    implicit: bool,
    /// A `G10` set the default before the program selected any.
    default_set: bool,
    /// Every offset set, selected or in force, with its origins (`None`: not known).
    table: Vec<(String, [Option<Origin>; AXES])>,
    external: [Origin; AXES],
    /// `G52`, toolpath coordinates (known: the program gives it); LinuxCNC's `G92` too.
    local: [f64; AXES],
    /// Fanuc's `G92` shift of every offset, toolpath coordinates (known: the program gives the
    /// position it makes the current one).
    position: [f64; AXES],
    /// Per axis, the bases at the last point checked.
    last: [Option<Key>; AXES],
    /// The offset the program selected last before its first point: the start, by its name.
    start_named: Option<String>,
}

impl WorkOffsets {
    /// At the start: the control's default offset `default` in force (`G54`), nothing set.
    pub(super) fn new(default: &str) -> WorkOffsets {
        WorkOffsets {
            active: default.to_string(),
            active_k: 0,
            implicit: true,
            default_set: false,
            table: vec![(default.to_string(), std::array::from_fn(|_| Some(START)))],
            external: std::array::from_fn(|_| START),
            local: [0.0; AXES],
            position: [0.0; AXES],
            last: std::array::from_fn(|_| None),
            start_named: None,
        }
    }

    /// The start's name where the program selects it before its first point (`None`: the
    /// control's default, which the program does not name).
    pub(super) fn start_named(&self) -> Option<&str> {
        self.start_named.as_deref()
    }

    /// The offset in force.
    pub(super) fn active(&self) -> &str {
        &self.active
    }

    fn index(&self, name: &str) -> Option<usize> {
        self.table.iter().position(|(n, _)| n == name)
    }

    /// The origin of the offset in force on `axis` (always known: the start, set, or taken
    /// as equal to the one before it when selected).
    fn active_origin(&self, axis: usize) -> &Origin {
        self.table
            .get(self.active_k)
            .and_then(|(_, o)| o[axis].as_ref())
            .unwrap_or(&START)
    }

    /// How far the offsets in force shift program coordinates, toolpath coordinates (mm,
    /// degrees): the offset's origin, the external offset, `G52` and `G92`.
    pub(super) fn shift(&self) -> [f64; AXES] {
        std::array::from_fn(|i| {
            self.active_origin(i).value + self.external[i].value + self.local[i] + self.position[i]
        })
    }

    /// The origin of the offset in force (with the external offset), X Y Z, toolpath
    /// coordinates: [`Self::shift`] without `G52` and `G92`.
    pub(super) fn origin(&self) -> [f64; 3] {
        std::array::from_fn(|i| self.active_origin(i).value + self.external[i].value)
    }

    /// Whether the program gave the origin of the offset in force on X, Y or Z (a `G10`),
    /// rather than it being the start offset's or taken as equal to the one before.
    pub(super) fn origin_given(&self) -> bool {
        (0..3).any(|i| {
            let o = self.active_origin(i);
            o.basis == Basis::Machine || (!o.assumed && o.value != 0.0)
        })
    }

    /// Fanuc's `G92` shift on `axis`.
    pub(super) fn position(&self, axis: usize) -> f64 {
        self.position[axis]
    }

    /// Sets Fanuc's `G92` shift on `axis`.
    pub(super) fn set_position(&mut self, axis: usize, value: f64) {
        self.position[axis] = value;
    }

    /// `G52`'s shift on `axis`.
    pub(super) fn local(&self, axis: usize) -> f64 {
        self.local[axis]
    }

    /// Sets `G52`'s shift on `axis`.
    pub(super) fn set_local(&mut self, axis: usize, value: f64) {
        self.local[axis] = value;
    }

    /// Selects offset `name` (`G55`). `Some(warning)` when the move to the next point is sized
    /// by an assumption on one of `axes` (those the program uses): the new offset (or the one
    /// before) was never set there, and is taken as equal to the other.
    pub(super) fn select(&mut self, name: &str, axes: std::ops::Range<usize>) -> Option<String> {
        // Before the first point, a selection still names the start: nothing has been made
        // in the offset it replaces (a Sinumerik header's `G500`, then `G54`).
        let before_points = self.last.iter().all(Option::is_none);
        if before_points {
            self.start_named = Some(name.to_string());
        }
        let implicit = std::mem::replace(&mut self.implicit, false) || before_points;
        if name == self.active {
            return None;
        }
        let known = self.index(name).is_some();
        if implicit && !known && !self.default_set {
            // The program names the offset it starts in.
            if let Some((n, _)) = self.table.get_mut(self.active_k) {
                *n = name.to_string();
            }
            self.active = name.to_string();
            return None;
        }
        let before: [Origin; AXES] = std::array::from_fn(|i| self.active_origin(i).clone());
        let prev = std::mem::replace(&mut self.active, name.to_string());
        let k = self.entry(name);
        self.active_k = k;
        let mut assumed = false;
        for (i, (slot, mut old)) in self.table[k].1.iter_mut().zip(before).enumerate() {
            let said = axes.contains(&i);
            assumed |= said && old.assumed;
            match slot {
                Some(o) => assumed |= said && o.assumed,
                None => {
                    // Never set: taken as equal to the offset in force until now.
                    old.assumed = true;
                    *slot = Some(old);
                    assumed |= said;
                }
            }
        }
        assumed.then(|| {
            format!(
                "{name}: another work offset than {prev}, whose values feedopt does not know: \
                 the move to the next point is sized as if the two were equal (the program's \
                 coordinates are used as written)"
            )
        })
    }

    /// The index in `table` of offset `name`, added (origins unknown) if it is not there.
    fn entry(&mut self, name: &str) -> usize {
        self.index(name).unwrap_or_else(|| {
            self.table
                .push((name.to_string(), std::array::from_fn(|_| None)));
            self.table.len() - 1
        })
    }

    /// Sets `target`'s origin on `axis` (a `G10`, `cause`). An increment of an origin not
    /// known leaves it unknown.
    pub(super) fn set(&mut self, target: &Target, axis: usize, how: Setting, cause: &Cause) {
        let here_origin = self.active_origin(axis).clone();
        let external = self.external[axis].value;
        let local = self.local[axis];
        let slot: &mut Option<Origin> = match target {
            Target::External => {
                let e = &mut self.external[axis];
                match how {
                    Setting::Machine(v) => *e = Origin::machine(v, cause),
                    Setting::Increment(d) => e.value += d,
                    Setting::Position { here, given } => {
                        e.value = here - here_origin.value - local - given;
                    }
                }
                return;
            }
            Target::Offset(name) => {
                if self.implicit && *name == self.active {
                    self.default_set = true;
                }
                let k = self.entry(name);
                &mut self.table[k].1[axis]
            }
        };
        match how {
            Setting::Machine(v) => *slot = Some(Origin::machine(v, cause)),
            Setting::Increment(d) => {
                if let Some(o) = slot {
                    o.value += d;
                }
            }
            Setting::Position { here, given } => {
                // The current position lies on the basis of the offset in force: so does the
                // new origin.
                // Set by the program, so not an assumption of its own (the basis may be).
                *slot = Some(Origin {
                    value: here - external - local - given,
                    assumed: false,
                    ..here_origin
                });
            }
        }
    }

    /// The bases a point made now is on, per axis.
    fn bases(&self, axis: usize) -> (Basis, Basis) {
        (self.active_origin(axis).basis, self.external[axis].basis)
    }

    /// The bases a point made now is on, and the cause of a machine basis, per axis.
    fn key(&self, axis: usize) -> Key {
        let o = self.active_origin(axis);
        let e = &self.external[axis];
        let cause = o.cause.clone().or_else(|| e.cause.clone());
        ((o.basis, e.basis), cause)
    }

    /// A point is made now in program coordinates: its ends' bases on `axes` must be those of
    /// the point before (see the module docs).
    pub(super) fn check(&mut self, axes: std::ops::Range<usize>) -> Result<(), Mismatch> {
        for axis in axes {
            // Every point comes here: the usual case, the same bases, costs no clone.
            if matches!(&self.last[axis], Some((before, _)) if *before == self.bases(axis)) {
                continue;
            }
            let now = self.key(axis);
            match &self.last[axis] {
                Some((before, cause)) if *before != now.0 => {
                    let machine =
                        |k: (Basis, Basis)| k.0 == Basis::Machine || k.1 == Basis::Machine;
                    let ends_on_machine = machine(now.0) && !machine(*before);
                    return Err(Mismatch {
                        axis,
                        cause: if ends_on_machine || cause.is_none() {
                            now.1.clone()
                        } else {
                            cause.clone()
                        },
                        ends_on_machine,
                    });
                }
                _ => self.last[axis] = Some(now),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cause(line: usize) -> Cause {
        Cause {
            line,
            text: "G10".into(),
            offset: "G54".into(),
        }
    }

    #[test]
    fn the_first_selection_names_the_start_and_a_later_one_is_assumed_equal() {
        let mut o = WorkOffsets::new("G54");
        assert_eq!(o.select("G55", 0..3), None);
        assert_eq!(o.active(), "G55");
        // Before the first point, another selection still names the start.
        assert_eq!(o.select("G57", 0..3), None);
        assert_eq!(o.active(), "G57");
        assert_eq!(o.select("G55", 0..3), None);
        // A point made in it, then a change: assumed equal, said.
        assert!(o.check(0..3).is_ok());
        assert!(o.select("G56", 0..3).is_some_and(|w| w.contains("G55")));
        assert_eq!(o.shift(), [0.0; AXES]);
        // Back to G55: the move is sized by the same assumption, so it is said again.
        assert!(o.select("G55", 0..3).is_some());
    }

    #[test]
    fn two_offsets_set_in_machine_coordinates_lie_that_far_apart() {
        let mut o = WorkOffsets::new("G54");
        for (name, x) in [("G54", 100.0), ("G55", 250.0)] {
            for axis in 0..3 {
                let v = if axis == 0 { x } else { 0.0 };
                o.set(
                    &Target::Offset(name.into()),
                    axis,
                    Setting::Machine(v),
                    &cause(1),
                );
            }
        }
        assert_eq!(o.shift()[0], 100.0);
        assert!(o.check(0..3).is_ok());
        // Both known: no assumption, no warning; the shift follows.
        assert_eq!(o.select("G55", 0..3), None);
        assert_eq!(o.shift()[0], 250.0);
        assert!(o.check(0..3).is_ok());
    }

    #[test]
    fn a_machine_value_after_moves_on_the_start_is_a_mismatch_at_the_next_point() {
        let mut o = WorkOffsets::new("G54");
        assert!(o.check(0..3).is_ok());
        o.set(
            &Target::Offset("G54".into()),
            0,
            Setting::Machine(100.0),
            &cause(3),
        );
        let m = o.check(0..3).unwrap_err();
        assert_eq!(m.axis, 0);
        assert!(m.ends_on_machine);
        assert_eq!(m.cause, Some(cause(3)));
        // An increment or a position-relative setting stays on the start: no mismatch.
        let mut o = WorkOffsets::new("G54");
        assert!(o.check(0..3).is_ok());
        o.set(
            &Target::Offset("G54".into()),
            0,
            Setting::Increment(5.0),
            &cause(3),
        );
        o.set(
            &Target::Offset("G54".into()),
            1,
            Setting::Position {
                here: 7.0,
                given: 0.0,
            },
            &cause(3),
        );
        assert_eq!(o.shift()[..2], [5.0, 7.0]);
        assert!(o.check(0..3).is_ok());
    }

    #[test]
    fn the_external_offset_adds_to_every_offset() {
        let mut o = WorkOffsets::new("G54");
        o.set(&Target::External, 2, Setting::Increment(-1.5), &cause(1));
        o.set_local(2, 0.5);
        assert_eq!(o.shift()[2], -1.0);
        assert!(o.check(0..3).is_ok());
    }
}
