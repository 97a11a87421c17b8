//! Simulation with compliant drives: the flexible-joint model (M. W. Spong, "Modeling and
//! control of elastic joint robots", J. Dyn. Sys. Meas. Control 109, 1987). Each elastic
//! drive on a coordinate q_k gets its rotor as a coordinate of its own, theta_k (rad, joint
//! side: the motor angle over n), with inertia n^2 J; the spring and damper of its
//! transmission join the two:
//!
//!   A(q) qdd = b(q, qd) + k (theta - q) + c (thetad - qd),        (the mechanism, rotors out)
//!   n^2 J thetadd = n t_m - k (theta - q) - c (thetad - qd),       (each rotor)
//!
//! t_m the model's drive on the coordinate (the motor torque, N m, motor side; an ideal
//! transmission: no efficiency or motor friction). The energy
//! E = T + V + sum 1/2 n^2 J thetad^2 + 1/2 k (theta - q)^2 changes only by the motors' work
//! W = int sum n t_m thetad dt, the transmission dampers' loss D = int sum c (thetad - qd)^2 dt
//! (both integrated with the run, as two more states) and the model's own dampers and
//! friction: E(t) - E(0) = W - D where the model has none. As k grows the run tends to the
//! rigid model's, whose A holds n^2 J.

use crate::dynamics::{forward, kinetic_energy, potential_energy, Drives, FixedDrives, ModelDrives};
use crate::integrate::{Method, OdeSystem, Options, Stepper};
use crate::kinematics::assemble_into;
use crate::model::compliance::DriveCompliance;
use crate::model::Mechanism;
use crate::Workspace;
use crate::{Error, KinematicsError};

/// Most output times of a run: 1e7 rows of a few numbers, ~1 GB at most.
const MAX_OUTPUTS: f64 = 1e7;

/// A run: the output times (s), and per time the coordinates q, rates qd (m each), the rotors'
/// angles theta and rates (one per elastic drive; rad or m, joint side), the energy E, the
/// motors' work W since the start and the transmission dampers' loss D (J).
#[derive(Debug, Clone, PartialEq)]
pub struct FlexibleRun {
    pub t: Vec<f64>,
    pub q: Vec<Vec<f64>>,
    pub qd: Vec<Vec<f64>>,
    pub theta: Vec<Vec<f64>>,
    pub thetad: Vec<Vec<f64>>,
    pub energy: Vec<f64>,
    pub work: Vec<f64>,
    pub dissipated: Vec<f64>,
}

/// The flexible-joint model as an ODE in y = [q, qd, theta, thetad, W, D] (2 (m + r) + 2, r
/// elastic drives; W and D the motors' work and the dampers' loss): the mechanism without its
/// rotors, the elastic drives, and the buffers of an evaluation (none is allocated in one).
pub struct FlexibleOde<'m> {
    rigid: Mechanism,
    model: &'m Mechanism,
    drives: Vec<DriveCompliance>,
    ratios: Vec<f64>,
    ws: Workspace,
    /// (m) The springs' and dampers' efforts on the coordinates (joint side), and the model's
    /// drives (the motor torques, motor side).
    spring: Vec<f64>,
    motor: Vec<f64>,
}

impl<'m> FlexibleOde<'m> {
    /// The model's flexible-joint system and its start y0 (the model's start, rotors at their
    /// joints' angles and rates: springs relaxed). Every elastic drive must be on a
    /// coordinate, with a rotor (J > 0).
    pub fn new(mech: &'m Mechanism) -> Result<(Self, Vec<f64>), Error> {
        let drives = mech.compliance.drives.clone();
        if drives.is_empty() {
            return Err(refuse("a model with `compliance.drives` (docs/stiffness.md)", "no elastic drive".into()));
        }
        if let Some(d) = drives.iter().find(|d| d.actuator >= mech.dof() || d.rotor_inertia <= 0.0) {
            let name = mech.actuator_names()[d.actuator].clone();
            return Err(refuse(
                "elastic drives on coordinates with a rotor (`actuators`: `rotor_inertia` > 0)",
                format!("actuator '{name}' without one"),
            ));
        }
        let mut rigid = mech.clone();
        // The rotors are coordinates of their own: out of A, and the drives are the springs.
        rigid.actuators = vec![None; mech.dof()];
        let ratios = drives.iter().map(|d| mech.actuators[d.actuator].as_ref().map_or(1.0, |a| a.ratio)).collect();
        let mut ws = Workspace::new(&rigid);
        let (q0, qd0) = mech.initial_state();
        assemble_into(&rigid, &q0, &mut ws)?;
        let m = mech.dof();
        let mut y: Vec<f64> = q0.iter().chain(&qd0).copied().collect();
        y.extend(drives.iter().map(|d| q0[d.actuator]));
        y.extend(drives.iter().map(|d| qd0[d.actuator]));
        y.extend([0.0, 0.0]);
        let ode = FlexibleOde { rigid, model: mech, drives, ratios, ws, spring: vec![0.0; m], motor: vec![0.0; m] };
        Ok((ode, y))
    }

    /// The energy E (J) at y.
    fn energy(&mut self, y: &[f64]) -> Result<f64, KinematicsError> {
        let (m, r) = (self.rigid.dof(), self.drives.len());
        let (q, qd) = (&y[..m], &y[m..2 * m]);
        let (th, thd) = (&y[2 * m..2 * m + r], &y[2 * m + r..2 * (m + r)]);
        crate::dynamics::kinematic_stages(&self.rigid, q, qd, &mut self.ws)?;
        let mut e = kinetic_energy(&self.rigid, &self.ws.xd) + potential_energy(&self.rigid, &self.ws.x);
        for (i, d) in self.drives.iter().enumerate() {
            let stretch = th[i] - q[d.actuator];
            e += 0.5 * d.rotor_inertia * thd[i] * thd[i] + 0.5 * d.stiffness * stretch * stretch;
        }
        Ok(e)
    }
}

impl OdeSystem for FlexibleOde<'_> {
    type Error = Error;
    fn dim(&self) -> usize {
        2 * (self.rigid.dof() + self.drives.len()) + 2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        let (m, r) = (self.rigid.dof(), self.drives.len());
        let (q, qd) = (&y[..m], &y[m..2 * m]);
        let (th, thd) = (&y[2 * m..2 * m + r], &y[2 * m + r..2 * (m + r)]);
        // Each spring's effort: on its coordinate, and against its rotor (the motor's added below).
        self.spring.fill(0.0);
        for (i, d) in self.drives.iter().enumerate() {
            let k = d.actuator;
            let own = d.stiffness * (th[i] - q[k]) + d.damping * (thd[i] - qd[k]);
            self.spring[k] += own;
            dy[2 * m + r + i] = -own;
        }
        ModelDrives(self.model).efforts(t, q, qd, &mut self.motor).map_err(|message| Error::Drive { t, message })?;
        forward(&self.rigid, t, q, qd, &mut FixedDrives(&self.spring), &mut self.ws)?;
        dy[..m].copy_from_slice(qd);
        dy[m..2 * m].copy_from_slice(&self.ws.qdd);
        dy[2 * m..2 * m + r].copy_from_slice(thd);
        let (mut power, mut loss) = (0.0, 0.0);
        for (i, d) in self.drives.iter().enumerate() {
            let torque = self.ratios[i] * self.motor[d.actuator];
            let rotor = &mut dy[2 * m + r + i];
            *rotor = (torque + *rotor) / d.rotor_inertia;
            power += torque * thd[i];
            let slip = thd[i] - qd[d.actuator];
            loss += d.damping * slip * slip;
        }
        dy[2 * (m + r)] = power;
        dy[2 * (m + r) + 1] = loss;
        Ok(())
    }
}

fn refuse(expected: &str, got: String) -> Error {
    KinematicsError::BadArgument { name: "mechanism", expected: expected.into(), got }.into()
}

/// Simulate the flexible-joint model ([`FlexibleOde`]) from the model's start (rotors at their
/// joints' angles, springs relaxed) to `t_end` (s) with `method` at tolerances `options`,
/// output every `output_dt` (s). Every elastic drive must be on a coordinate, with a rotor
/// (J > 0).
pub fn simulate_flexible(
    mech: &Mechanism,
    t_end: f64,
    output_dt: f64,
    method: Method,
    options: &Options,
) -> Result<FlexibleRun, Error> {
    let (mut sys, y) = FlexibleOde::new(mech)?;
    if !(t_end > 0.0 && t_end.is_finite() && output_dt > 0.0 && t_end / output_dt <= MAX_OUTPUTS) {
        return Err(refuse(
            "t_end > 0 and output_dt > 0 (s), at most 1e7 outputs",
            format!("t_end {t_end}, output_dt {output_dt}"),
        ));
    }
    let mut stepper = Stepper::new(method, options, y.len()).map_err(Error::Options)?;
    stepper
        .reset(&mut sys, 0.0, &y)
        .map_err(|e| Error::Options(format!("the flexible-joint run failed at its start: {e}")))?;
    let mut run = FlexibleRun {
        t: vec![],
        q: vec![],
        qd: vec![],
        theta: vec![],
        thetad: vec![],
        energy: vec![],
        work: vec![],
        dissipated: vec![],
    };
    let n_out = (t_end / output_dt).floor() as usize;
    let mut out = vec![0.0; y.len()];
    for j in 0..=n_out {
        let t = (j as f64 * output_dt).min(t_end);
        while stepper.t() < t {
            stepper.step(&mut sys, t_end).map_err(|e| Error::Options(format!("the flexible-joint run failed: {e}")))?;
        }
        stepper.interpolate(&mut sys, t, &mut out);
        let (m, r) = (mech.dof(), sys.drives.len());
        run.t.push(t);
        run.q.push(out[..m].to_vec());
        run.qd.push(out[m..2 * m].to_vec());
        run.theta.push(out[2 * m..2 * m + r].to_vec());
        run.thetad.push(out[2 * m + r..2 * (m + r)].to_vec());
        run.energy.push(sys.energy(&out)?);
        run.work.push(out[2 * (m + r)]);
        run.dissipated.push(out[2 * (m + r) + 1]);
    }
    Ok(run)
}
