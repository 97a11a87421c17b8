//! The motors' gears held on one side of their at-rest bands through a run's steps, as
//! Simulink holds a block's mode and locates its zero crossings. Chosen afresh at every
//! evaluation (`transmission::Band`), a gear's law jumps inside a step where its coordinate's
//! rate enters the band and the gear sticks (qdd from the moving solution to -qd / T), a
//! discontinuity of the right-hand side that no embedded error estimate sees: the five-bar
//! robot's rows jumped inside steps (its efforts -2.38 -> -3.87 N m and back at t = 0.745 s,
//! DOP853 rtol 4.47e-6) and its drift over 1 s stood out 35000x from its neighbours'.
//!
//! Held, each band's law is smooth in the state (`dynamics::gears`: the modes within it meet
//! continuously, motoring and back-driven at tau = 0, sticking and slipping at zero slip). A
//! moving gear's entry n s qd - v_m ([`Band::entry`]) is a switching function: where it
//! changes sign inside a step, the crossing is located on the step's interpolant
//! ([`locate_zero`], to [`super::events::EVENT_XTOL`]), the step is taken again to end there,
//! the gear is held at rest and the integrator restarted. Leaving the band needs no restart:
//! a gear leaves it slipping outwards, where the at-rest law and the moving one are the same
//! equations (motoring or back-driven along qd), so it is switched at the accepted point.
//!
//! **Chattering.** A gear is switched back out of the band only once its motor turns
//! [`EXIT_MARGIN`] faster than its stiction speed: entered at the located crossing, its state
//! lies on the edge to the run's tolerance, on either side, and a gear sliding along the edge
//! (held at its stuck band's boundary, the sliding mode `transmission::STUCK_DECAY` describes)
//! stays on the at-rest side, whose law covers that motion smoothly.

use super::events::locate_zero;
use super::ode::MechanismOde;
use crate::dynamics::transmission::Band;
use crate::integrate::Stepper;
use crate::kinematics::Chart;
use crate::Error;

/// A gear held at rest is switched to moving once its motor's speed |n qd| exceeds its
/// stiction speed v_m by this fraction: a hysteresis far above the tolerance to which an entry
/// is located, and small beside the band (the motor's Coulomb torque, tanh(n qd / v_m), is
/// 0.77 of its full value at the edge, 0.77 at 1.01 v_m too).
pub const EXIT_MARGIN: f64 = 1e-2;

/// The entry located inside the last step taken: its time, the retaken step's end, and the
/// motor that enters its band there.
#[derive(Debug, Clone, Copy, Default)]
pub struct GearSides {
    entry: Option<(f64, usize)>,
}

impl GearSides {
    /// Hold every motor on the side of the point in `ode.ws` (the run's start).
    pub fn hold_all(ode: &mut MechanismOde) {
        let sides: Vec<Band> = ode.ws.losses.gears().sides(ode.mech).map(|(_, b, _, _)| b).collect();
        for (i, band) in sides.into_iter().enumerate() {
            ode.hold_gear(i, Some(band));
        }
    }

    /// The earliest entry of a moving gear into its at-rest band inside the step the stepper
    /// just took from (`t0`, `y0`), located on its interpolant (`yi` its scratch); `None`
    /// without one, and in the step taken again to end at an entry located before: that
    /// step's crossing is that entry, at its end.
    pub fn entry_in_step(
        &mut self,
        ode: &mut MechanismOde,
        stepper: &mut Stepper,
        y0: &[f64],
        yi: &mut [f64],
    ) -> Result<Option<f64>, Error> {
        let (t0, t1) = (stepper.t_prev(), stepper.t());
        if !ode.ws.losses.gears().has_motors() || self.entry.is_some_and(|(t, _)| t1 >= t) {
            return Ok(None);
        }
        let m = ode.m();
        let n = ode.ws.losses.gears().sides(ode.mech).count();
        let direct = ode.ws.chart == Chart::Inputs && ode.motion.is_none();
        let direct = direct && ode.ws.losses.gears().sides(ode.mech).all(|(k, ..)| k < m);
        // Read from the states, unless a motor's rate needs an evaluation (put back after).
        let saved = (!direct).then(|| ode.save());
        yi.copy_from_slice(stepper.y());
        let mut first: Option<(f64, usize)> = None;
        for i in 0..n {
            let end = entry(ode, i, t1, yi)?;
            if !end.is_some_and(|g| g <= 0.0) {
                continue;
            }
            let start = entry(ode, i, t0, y0)?.filter(|&g| g > 0.0);
            let (Some(g0), Some(g1)) = (start, end) else { continue };
            let t = locate_zero(
                |s| {
                    stepper.interpolate(ode, s, yi);
                    entry(ode, i, s, yi).map(|g| g.unwrap_or(1.0))
                },
                (t0, t1),
                (g0, g1),
            )?;
            if first.is_none_or(|(tf, _)| t < tf) {
                first = Some((t, i));
            }
        }
        match first {
            Some(found) => {
                self.entry = Some(found);
                Ok(Some(found.0))
            }
            None => {
                // No entry: the step's evaluations stand, to the bit.
                if let Some(saved) = saved {
                    ode.restore(saved);
                }
                Ok(None)
            }
        }
    }

    /// At the point accepted at `t` (evaluated in `ode.ws`): the gear whose entry the step
    /// ended at held at rest, and gears at rest that turn [`EXIT_MARGIN`] past their band held
    /// moving. True when the law changed discontinuously there: restart the integrator.
    pub fn switch(&mut self, ode: &mut MechanismOde, t: f64) -> bool {
        // The retaken step ends on the entry exactly; a crossing of a change point that
        // restarted the run past it drops it.
        let entered = self.entry.filter(|&(te, _)| t == te).map(|(_, i)| i);
        if self.entry.is_some_and(|(te, _)| t >= te) {
            self.entry = None;
        }
        let sides: Vec<(Band, f64)> = ode
            .ws
            .losses
            .gears()
            .sides(ode.mech)
            .map(|(_, band, a, qd)| (band, a.ratio * qd / a.stiction_speed))
            .collect();
        for (i, (band, speed)) in sides.into_iter().enumerate() {
            if Some(i) == entered {
                ode.hold_gear(i, Some(Band::AtRest));
            } else if band == Band::AtRest && speed.abs() > 1.0 + EXIT_MARGIN {
                ode.hold_gear(i, Some(Band::Moving(speed.signum())));
            }
        }
        entered.is_some()
    }
}

/// Motor i's entry function ([`Band::entry`]) at state y (`None` at rest): qd read from y in the
/// user's chart for a coordinate's motor, else from an evaluation there.
fn entry(ode: &mut MechanismOde, i: usize, t: f64, y: &[f64]) -> Result<Option<f64>, Error> {
    let m = ode.m();
    let (k, band, a, _) = ode.ws.losses.gears().sides(ode.mech).nth(i).expect("motor i exists");
    let direct = k < m && ode.ws.chart == Chart::Inputs && ode.motion.is_none();
    let qd = if direct {
        y[m + k]
    } else {
        ode.evaluate_walking(t, y)?;
        ode.ws.losses.gears().sides(ode.mech).nth(i).expect("motor i exists").3
    };
    Ok(band.entry(a, qd))
}
