//! The motors' gears held on one side of their at-rest bands through a run's steps, as
//! Simulink holds a block's mode and locates its zero crossings. Chosen afresh at every
//! evaluation (`transmission::Band`), a gear's law jumps inside a step where its coordinate's
//! rate enters the band and the gear sticks (qdd from the moving solution to -qd / T), a
//! discontinuity of the right-hand side that no embedded error estimate sees: the five-bar
//! robot's rows jumped inside steps (its efforts -2.38 -> -3.87 N m and back at t = 0.745 s,
//! DOP853 rtol 4.47e-6) and its drift over 1 s stood out 35000x from its neighbours'.
//!
//! Held, each side's law is smooth in the state (`dynamics::gears`: the modes within it meet
//! continuously, motoring and back-driven at tau = 0, sticking and slipping at zero slip).
//! Each side's switching function ([`Band::switching`]) is watched: where one changes sign
//! inside a step, its zero is located on the step's interpolant ([`locate_zero`], to
//! [`super::events::EVENT_XTOL`]), the step is taken again to end there, and the gear is
//! switched. Past its edge a side's law is no motion's (the at-rest one decides the branch by
//! qdd + qd / T, which a decelerating gear far outside the band gets wrong), so the interpolant
//! of a step that went far past it is off there too: the step taken again is checked as any
//! other, and only an end within [`END_WINDOW`] of the edge counts as the switch. Entering the
//! band the law jumps (the gear may stick): the integrator restarts. Leaving it the gear slips
//! outwards, where both sides' laws are the same equations (motoring or back-driven along qd):
//! no restart.
//!
//! **Chattering.** A gear leaves the band only [`EXIT_MARGIN`] past its edge, so a gear that
//! entered at the located edge (to [`END_WINDOW`]) is not switched back by the tolerance-sized
//! offset of its state, and one sliding along the edge (held at its stuck band's boundary, the
//! sliding mode `transmission::STUCK_DECAY` describes) stays at rest, whose law covers that
//! motion smoothly.

use super::events::locate_zero;
use super::ode::MechanismOde;
use crate::dynamics::transmission::Band;
use crate::integrate::Stepper;
use crate::kinematics::Chart;
use crate::Error;

/// A gear at rest leaves its band once its motor turns this fraction faster than its stiction
/// speed v_m: a hysteresis far above the tolerance to which a switch is located, and small
/// beside the band (the motor's Coulomb torque, T_c tanh(n qd / v_m), is 0.762 T_c at the
/// edge, 0.766 T_c at 1.01 v_m).
pub const EXIT_MARGIN: f64 = 1e-2;

/// A step taken again to end at a located switch makes it when its end's switching function
/// lies within this fraction of v_m of 0 (half the hysteresis: the other side's function then
/// starts at least as far from its own zero).
pub const END_WINDOW: f64 = 0.5 * EXIT_MARGIN;

/// The switch located inside the last step taken: its time (the retaken step's end) and the
/// motor that switches there.
#[derive(Debug, Clone, Copy, Default)]
pub struct GearSides {
    switch: Option<(f64, usize)>,
}

impl GearSides {
    /// Hold every motor on the side of the point in `ode.ws` (the run's start).
    pub fn hold_all(ode: &mut MechanismOde) {
        let sides: Vec<Band> = ode.ws.losses.gears().sides(ode.mech).map(|(_, b, _, _)| b).collect();
        for (i, band) in sides.into_iter().enumerate() {
            ode.hold_gear(i, Some(band));
        }
    }

    /// The earliest switch of a gear's side inside the step the stepper just took from
    /// (`t0`, `y0`), located on its interpolant (`yi` its scratch), for the step to be taken
    /// again to end there; `None` without one, or when the step (taken again) ends on it.
    pub fn switch_in_step(
        &mut self,
        ode: &mut MechanismOde,
        stepper: &mut Stepper,
        y0: &[f64],
        yi: &mut [f64],
    ) -> Result<Option<f64>, Error> {
        let (t0, t1) = (stepper.t_prev(), stepper.t());
        let retaken = self.switch.take().filter(|&(ts, _)| t1 == ts);
        let n = ode.ws.losses.gears().sides(ode.mech).count();
        // A prescribed coordinate's gear has no side (its switching function would only cost
        // evaluations, and one failing there would end the run).
        if !(0..n).any(|i| ode.ws.losses.gears().free(i)) {
            return Ok(None);
        }
        // Read from the states, unless a motor's rate needs an evaluation (put back after).
        let direct = ode.ws.losses.gears().sides(ode.mech).all(|(k, ..)| rate_in_state(ode, k));
        let saved = (!direct).then(|| ode.save());
        yi.copy_from_slice(stepper.y());
        let mut first: Option<(f64, usize)> = None;
        for i in 0..n {
            if !ode.ws.losses.gears().free(i) {
                continue;
            }
            let (g1, window) = switching(ode, i, t1, yi)?;
            if retaken.is_some_and(|(_, j)| j == i) && g1.abs() <= window {
                first = Some((t1, i));
                continue;
            }
            if g1 > 0.0 {
                continue;
            }
            let (g0, _) = switching(ode, i, t0, y0)?;
            if g0 <= 0.0 {
                // Past its edge from the step's start (no zero to locate): switched at its end
                // rather than held on a side it has left.
                first.get_or_insert((t1, i));
                continue;
            }
            let locate = |s| {
                stepper.interpolate(ode, s, yi);
                switching(ode, i, s, yi).map(|(g, _)| g)
            };
            let t = locate_zero(locate, (t0, t1), (g0, g1))?;
            if first.is_none_or(|(tf, _)| t < tf) {
                first = Some((t, i));
            }
        }
        self.switch = first;
        if let Some((t, _)) = first.filter(|&(t, _)| t < t1) {
            return Ok(Some(t));
        }
        // No switch inside the step (or one at its end): its evaluations stand, to the bit.
        if let Some(saved) = saved {
            ode.restore(saved);
        }
        Ok(None)
    }

    /// At the point accepted at `t` (evaluated in `ode.ws`): switch the gear whose switch the
    /// step ended at. True when it entered its band, where the law jumps: restart the
    /// integrator.
    pub fn switch(&mut self, ode: &mut MechanismOde, t: f64) -> bool {
        let Some((_, i)) = self.switch.take().filter(|&(ts, _)| t == ts) else { return false };
        let (_, band, _, qd) = ode.ws.losses.gears().sides(ode.mech).nth(i).expect("motor i exists");
        let next = match band {
            Band::AtRest => Band::Moving(qd.signum()),
            Band::Moving(_) => Band::AtRest,
        };
        ode.hold_gear(i, Some(next));
        next == Band::AtRest
    }
}

/// Motor i's switching function ([`Band::switching`]) at state y and its [`END_WINDOW`]: qd
/// read from y in the user's chart for a coordinate's motor, else from an evaluation there.
fn switching(ode: &mut MechanismOde, i: usize, t: f64, y: &[f64]) -> Result<(f64, f64), Error> {
    let (k, band, a, _) = ode.ws.losses.gears().sides(ode.mech).nth(i).expect("motor i exists");
    let qd = if rate_in_state(ode, k) {
        y[ode.m() + k]
    } else {
        ode.evaluate_walking(t, y)?;
        ode.ws.losses.gears().sides(ode.mech).nth(i).expect("motor i exists").3
    };
    Ok((band.switching(a, qd, EXIT_MARGIN), END_WINDOW * a.stiction_speed))
}

/// Whether actuator k's rate is read from the state itself: a coordinate's, in the user's chart,
/// with no prescribed motion (which replaces the state's rates in the evaluation).
fn rate_in_state(ode: &MechanismOde, k: usize) -> bool {
    k < ode.m() && ode.ws.chart == Chart::Inputs && ode.motion.is_none()
}
