//! Events, as in scipy's `solve_ivp`: functions g(t, q, qd) whose zeros a run reports (and,
//! for a terminal event, stops at). A zero is found where g changes sign between two accepted
//! steps (in the event's direction), then located on that step's own interpolant (the dense
//! output, [`super::dense`]) by the Illinois variant of regula falsi, to [`EVENT_XTOL`].

use super::dense::DenseOutput;
use crate::error::Time;

/// An event's time is located to within `EVENT_XTOL * max(|t|, h)` (h the step holding it):
/// a few units in the last place of t, the accuracy to which the interpolant is a function
/// of t at all. The time is that of the zero of g on the interpolant, which is as accurate
/// as the integrator's dense output (its tolerance), not more.
pub const EVENT_XTOL: f64 = 4.0 * f64::EPSILON;
/// Most Illinois iterations; it converges superlinearly, 10-20 are usual.
const MAX_ITERATIONS: usize = 200;

/// g(t, q, qd) as a closure (t in s, q and qd (m,)).
pub type EventClosure<'e> = Box<dyn FnMut(f64, &[f64], &[f64]) -> Result<f64, String> + 'e>;

/// The function of an event.
pub enum EventFn<'e> {
    /// Coordinate `index` (rad or m) minus `value`: the coordinate crossing a value (an end stop).
    Coordinate { index: usize, value: f64 },
    /// g(t, q, qd), t in s, q and qd (m,); an Err stops the run with status `event_failed`.
    Function(EventClosure<'e>),
}

/// An event: its function, whether its first zero ends the run, and which crossings count.
pub struct Event<'e> {
    pub g: EventFn<'e>,
    /// Stop the run at the first zero (status `event`, final row at its time).
    pub terminal: bool,
    /// > 0: only zeros where g rises; < 0: only where it falls; 0: both.
    pub direction: f64,
}

impl Event<'_> {
    /// A coordinate crossing a value.
    pub fn coordinate(index: usize, value: f64, terminal: bool, direction: f64) -> Self {
        Event { g: EventFn::Coordinate { index, value }, terminal, direction }
    }

    /// g at (t, q, qd).
    pub fn value(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<f64, String> {
        let g = match &mut self.g {
            EventFn::Coordinate { index, value } => q[*index] - *value,
            EventFn::Function(f) => f(t, q, qd)?,
        };
        if g.is_finite() {
            Ok(g)
        } else {
            Err(format!("the event function returned {g} at t = {} s: it must return a finite number", Time(t)))
        }
    }

    /// Whether g going from `g0` to `g1` over a step is a zero of this event. A g that is
    /// exactly 0 at a step's start had its zero reported at the step before (or is the start).
    fn crosses(&self, g0: f64, g1: f64) -> bool {
        let up = g0 < 0.0 && g1 >= 0.0;
        let down = g0 > 0.0 && g1 <= 0.0;
        (up && self.direction >= 0.0) || (down && self.direction <= 0.0)
    }
}

/// The zeros found so far: for event i, its times (s) and the states there (m each, row-major).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EventRecords {
    pub t: Vec<Vec<f64>>,
    pub q: Vec<Vec<f64>>,
    pub qd: Vec<Vec<f64>>,
}

/// The events of a run and their last values.
pub struct Watch<'e> {
    pub events: Vec<Event<'e>>,
    g: Vec<f64>,
    pub records: EventRecords,
    q: Vec<f64>,
    qd: Vec<f64>,
}

impl<'e> Watch<'e> {
    pub fn new(events: Vec<Event<'e>>, m: usize) -> Self {
        let n = events.len();
        Watch {
            events,
            g: vec![0.0; n],
            records: EventRecords { t: vec![Vec::new(); n], q: vec![Vec::new(); n], qd: vec![Vec::new(); n] },
            q: vec![0.0; m],
            qd: vec![0.0; m],
        }
    }

    /// The values of g at the start.
    pub fn start(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), String> {
        for (g, e) in self.g.iter_mut().zip(self.events.iter_mut()) {
            *g = e.value(t, q, qd)?;
        }
        Ok(())
    }

    /// Look for zeros in the integrator's step from t0 to the end of `dense` (its last piece or
    /// pieces), record them, and return the time and index of the first terminal one, if any
    /// (zeros after it are not recorded: the run ends there).
    pub fn step(&mut self, dense: &DenseOutput, t0: f64) -> Result<Option<(f64, usize)>, String> {
        let t1 = dense.t_end;
        dense.eval(t1, &mut self.q, &mut self.qd)?;
        let mut found: Vec<(f64, usize)> = Vec::new();
        for (i, e) in self.events.iter_mut().enumerate() {
            let g1 = e.value(t1, &self.q, &self.qd)?;
            if e.crosses(self.g[i], g1) {
                found.push((locate(e, dense, t0, t1, self.g[i], g1)?, i));
            }
            self.g[i] = g1;
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        let stop = found.iter().find(|&&(_, i)| self.events[i].terminal).copied();
        for &(t, i) in found.iter().filter(|&&(t, _)| stop.is_none_or(|(s, _)| t <= s)) {
            dense.eval(t, &mut self.q, &mut self.qd)?;
            self.records.t[i].push(t);
            self.records.q[i].extend_from_slice(&self.q);
            self.records.qd[i].extend_from_slice(&self.qd);
        }
        Ok(stop)
    }
}

/// The zero of `e` in [a, b] on the dense output, g(a) = ga != 0 and g(b) = gb of the other
/// sign or 0 ([`locate_zero`]).
fn locate(e: &mut Event, dense: &DenseOutput, a: f64, b: f64, ga: f64, gb: f64) -> Result<f64, String> {
    let m = dense.m;
    let (mut q, mut qd) = (vec![0.0; m], vec![0.0; m]);
    locate_zero(
        |c| {
            dense.eval(c, &mut q, &mut qd)?;
            e.value(c, &q, &qd)
        },
        (a, b),
        (ga, gb),
    )
}

/// The zero of g in [a, b], g(a) = ga != 0 and g(b) = gb of the other sign or 0, to
/// [`EVENT_XTOL`]: Illinois (regula falsi halving the weight of an end kept twice). Returns the
/// bracket's later end, where g has crossed.
pub(super) fn locate_zero<E>(
    mut g: impl FnMut(f64) -> Result<f64, E>,
    (mut a, mut b): (f64, f64),
    (mut ga, mut gb): (f64, f64),
) -> Result<f64, E> {
    let h = b - a;
    let mut side = 0;
    for _ in 0..MAX_ITERATIONS {
        if gb == 0.0 || (b - a) <= EVENT_XTOL * b.abs().max(a.abs()).max(h) {
            break;
        }
        let c = ((a * gb - b * ga) / (gb - ga)).clamp(a, b);
        // A secant point at an end (round-off) would not shrink the bracket: bisect.
        let c = if c <= a || c >= b { 0.5 * (a + b) } else { c };
        let gc = g(c)?;
        if gc == 0.0 || (gc < 0.0) != (ga < 0.0) {
            (b, gb) = (c, gc);
            if side == -1 {
                ga *= 0.5;
            }
            side = -1;
        } else {
            (a, ga) = (c, gc);
            if side == 1 {
                gb *= 0.5;
            }
            side = 1;
        }
    }
    Ok(b)
}
