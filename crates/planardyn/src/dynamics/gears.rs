//! The actuators' rotors and gears in forward and inverse dynamics (docs/actuators.md,
//! *Motors and transmissions*; the laws in [`super::transmission`]). Motor i drives its pair's
//! coordinate q_i (rate qd_i, qdd_i = g_i . zdd + h_i, g_i its row of D_x U) through a gear of
//! ratio n_i; its rotor turns at omega_r = omega_h + n_i qd_i, so omega_r' = w_i . zdd + r_i
//! with w_i = n_i g_i + e_i (e_i: the housing angle's row of D_x U, 0 for a fixed housing) and
//! r_i = n_i h_i + c_h. With c_i = t_m - f (motor torque less motor friction), t_i the torque
//! the rotor hands to the gear and tau_i the gear's output:
//!
//!   A zdd = b + sum_i [tau_i g_i + (t_i - c_i) e_i]    (the housing takes t - c = -J omega_r')
//!   t_i + J_i w_i . zdd = c_i - J_i r_i                (the rotor)
//!   motoring      tau_i - n eta t_i = 0,   valid while sigma tau_i >= 0
//!   back-driven   eta_b tau_i - n t_i = 0, valid while sigma tau_i <= 0 (eta_b = 0: t_i = 0,
//!                 the self-locking gear holds the load and the joint follows the rotor)
//!   stuck         qdd_i = 0 (at rest only), valid while tau_i lies between n eta t_i and
//!                 n t_i / eta_b (the gear's friction holds it)
//!
//! sigma is the direction of the relative motion (sgn qd_i; at rest sgn qdd_i). At rest means
//! the motor turning slower than its stiction speed v_m (`transmission::at_rest`), the band
//! where its Coulomb torque fades too: a joint that comes to rest under a load its gear holds
//! then sticks, its remaining speed decaying (qdd_i = -qd_i / T, `transmission::STUCK_DECAY`,
//! and sigma the sign of qdd_i + qd_i / T, the way it slips from that), where an exact
//! qd_i = 0 would make an integrator chatter across it (a sliding mode). With A factored,
//! zdd = y0 + sum_i (tau_i A^-1 g_i + t_i A^-1 e_i), so each choice of modes is a linear system
//! in the 2 N unknowns (tau_i, t_i). The choices are tried, the guess first (moving: motoring
//! when the motor's net torque pushes along the motion; at rest: stuck), and the first whose
//! solution lies in its branches is kept.
//!
//! **One solution.** With every housing fixed (e_i = 0), -tau_i is a monotone graph of
//! s_i = g_i . zdd: the gear's law tau = phi(t) is increasing in t (slopes n eta and n / eta_b,
//! vertical for eta_b = 0) and t = c - J n (s_i + h_i) decreases with s_i; at rest the stuck
//! band is the vertical segment where the slip is zero. So
//! A zdd - b - sum_i g_i tau_i(g_i . zdd) = 0 is the optimality condition of the strictly
//! convex function 1/2 zdd^T A zdd - b^T zdd plus sum_i Phi_i(g_i . zdd) (Phi_i' = -tau_i,
//! convex): exactly one zdd, whatever the number of motors; for one motor both branch
//! matrices, A + eta n^2 J g g^T and A + n^2 J g g^T / eta_b, are positive definite. A
//! housing on a moving link adds J e_i w_i^T, which is not symmetric when eta < 1: for one
//! motor each branch stays invertible with the same orientation while
//! 1 + J w^T A^-1 (eps n g + e) > 0 for eps = eta and 1 / eta_b, which fails only where the
//! housing turns against its rotor at nearly n times the joint's rate. Where no choice is
//! consistent (Painleve's paradox of friction), the evaluation is refused
//! ([`KinematicsError::GearsJammed`]) rather than guessed.

use super::transmission::{housing, motor_friction, motors, Band, STUCK_DECAY};
use crate::linalg::{lu_factor, lu_solve};
use crate::model::{Actuator, Mechanism};
use crate::KinematicsError;

/// Relative tolerance of a mode's branch test: a solution on the boundary of two modes
/// (sigma tau = 0, or qdd_i = 0 at rest) is in both up to the round-off of its terms, a few
/// eps of their size, which this accepts; far below any physical difference.
const MODE_TOL: f64 = 1e-12;

/// Below this pivot (relative to the largest entry) a choice of modes has no solution.
const PIVOT_TOL: f64 = 1e-14;

/// A gear's state in one evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Motoring,
    BackDriven,
    Stuck,
    /// Its coordinate follows a prescribed motion: the output is that motion's multiplier
    /// (`dynamics::prescribed`); here only the rotor's reaction on its housing.
    Prescribed,
}

const MOVING: &[Mode] = &[Mode::Motoring, Mode::BackDriven];
const AT_REST: &[Mode] = &[Mode::Motoring, Mode::BackDriven, Mode::Stuck];
const PRESCRIBED: &[Mode] = &[Mode::Prescribed];

/// Actuator k's rotor and gear at the last evaluation (zero without a motor).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Rotor {
    /// The motor torque t_m (N m) forward dynamics was given.
    pub torque: f64,
    /// The pair's rate qd_k and acceleration qdd_k (rad/s, rad/s^2 or m/s, m/s^2).
    pub rate: f64,
    pub accel: f64,
    /// The rotor's absolute acceleration omega_r' (rad/s^2), the housing's rate (rad/s).
    pub rotor_acc: f64,
    pub housing_rate: f64,
    /// qdd_k = g_k . zdd + h and omega_r' = w_k . zdd + r.
    h: f64,
    r: f64,
    /// c = t_m - f, the gear's input t (N m) and output tau (N m or N).
    pub net: f64,
    pub input: f64,
    pub output: f64,
}

/// The buffers of the motors' solve, sized once for N motors and m coordinates.
#[derive(Debug, Clone, Default)]
pub(crate) struct Gears {
    /// (N) the actuators with a motor, and each one's housing body.
    slots: Vec<usize>,
    housings: Vec<Option<usize>>,
    /// (n_a) every actuator's rotor.
    rotors: Vec<Rotor>,
    /// (N x m) e_i, A^-1 g_i and A^-1 e_i (homogeneous: prescribed coordinates held).
    e: Vec<f64>,
    ag: Vec<f64>,
    ae: Vec<f64>,
    /// (N x N) w_i . A^-1 g_l, w_i . A^-1 e_l, g_i . A^-1 g_l, g_i . A^-1 e_l; (N) w_i . y0, g_i . y0.
    wg: Vec<f64>,
    we: Vec<f64>,
    gg: Vec<f64>,
    ge: Vec<f64>,
    wy: Vec<f64>,
    gy: Vec<f64>,
    /// (2N x 2N) one choice's system, (2N) its solution and pivots.
    k: Vec<f64>,
    u: Vec<f64>,
    piv: Vec<usize>,
    /// (N) each motor's candidate modes, the guess's place among them, the odometer's digits.
    modes: Vec<&'static [Mode]>,
    first: Vec<usize>,
    digits: Vec<usize>,
    /// (N) each motor's side of its at-rest band as a run holds it (`None`: chosen from qd at
    /// each evaluation, as outside a run).
    held: Vec<Option<Band>>,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

impl Gears {
    pub(crate) fn new(mech: &Mechanism) -> Self {
        let slots: Vec<usize> = motors(mech).enumerate().filter_map(|(k, a)| a.map(|_| k)).collect();
        let (n, m) = (slots.len(), mech.dof());
        Gears {
            housings: slots.iter().map(|&k| housing(mech, k)).collect(),
            rotors: vec![Rotor::default(); motors(mech).count()],
            e: vec![0.0; n * m],
            ag: vec![0.0; n * m],
            ae: vec![0.0; n * m],
            wg: vec![0.0; n * n],
            we: vec![0.0; n * n],
            gg: vec![0.0; n * n],
            ge: vec![0.0; n * n],
            wy: vec![0.0; n],
            gy: vec![0.0; n],
            k: vec![0.0; 4 * n * n],
            u: vec![0.0; 2 * n],
            piv: vec![0; 2 * n],
            modes: vec![MOVING; n],
            first: vec![0; n],
            digits: vec![0; n],
            held: vec![None; n],
            slots,
        }
    }

    /// Every actuator's rotor (n_a; zeros without a motor) of the last evaluation.
    pub(crate) fn rotors(&self) -> &[Rotor] {
        &self.rotors
    }

    /// The motors: actuator index, housing row e (m) and rotor.
    pub(crate) fn each(&self, m: usize) -> impl Iterator<Item = (usize, &[f64], &Rotor)> {
        self.slots.iter().zip(self.e.chunks_exact(m.max(1))).map(|(&k, e)| (k, e, &self.rotors[k]))
    }

    fn actuator<'m>(&self, mech: &'m Mechanism, i: usize) -> &'m Actuator {
        motors(mech).nth(self.slots[i]).flatten().expect("a motor's slot has a motor")
    }

    /// Take the motor torques t_m of the drives out of `tau` (the coordinates', left 0: the
    /// gears turn them into efforts) and `pair_tau` (the pair actuators').
    pub(crate) fn take_torques(&mut self, tau: &mut [f64], pair_tau: &[f64]) {
        let m = tau.len();
        for &k in &self.slots {
            self.rotors[k].torque = if k < m { std::mem::take(&mut tau[k]) } else { pair_tau[k - m] };
        }
    }

    /// Each motor's kinematics at a point (after the kinematic stages: U (m x 3n), c and xd
    /// (3n)), `h(k)` = h_k of actuator k (qdd_k = g_k . zdd + h_k) and its rate `rates[k]`:
    /// h, e, r and the housing's rate.
    pub(crate) fn kinematics(
        &mut self,
        mech: &Mechanism,
        u: &[f64],
        c: &[f64],
        xd: &[f64],
        h: impl Fn(usize) -> f64,
        rates: &[f64],
    ) {
        let n = xd.len();
        let m = u.len() / n.max(1);
        for i in 0..self.slots.len() {
            let (k, ratio) = (self.slots[i], self.actuator(mech, i).ratio);
            let e = &mut self.e[i * m..(i + 1) * m];
            let h = h(k);
            let (c_h, omega_h) = match self.housings[i] {
                Some(b) => {
                    e.iter_mut().zip(u.chunks_exact(n)).for_each(|(e, u)| *e = u[3 * b + 2]);
                    (c[3 * b + 2], xd[3 * b + 2])
                }
                None => (0.0, 0.0),
            };
            let r = &mut self.rotors[k];
            (r.rate, r.h, r.r, r.housing_rate) = (rates[k], h, ratio * h + c_h, omega_h);
        }
    }

    /// Forward dynamics' set-up after [`Gears::kinematics`]: each motor's net torque c (0 where
    /// its coordinate is `prescribed`), its candidate modes, and the columns g_i, e_i (`gu`: the
    /// actuators' g, n_a x m) for the caller to turn into A^-1 g_i, A^-1 e_i ([`Gears::columns`])
    /// before [`Gears::products`].
    pub(crate) fn prepare(&mut self, mech: &Mechanism, gu: &[f64], m: usize, prescribed: impl Fn(usize) -> bool) {
        for i in 0..self.slots.len() {
            let (k, a) = (self.slots[i], self.actuator(mech, i));
            let prescribed = k < m && prescribed(k);
            let r = &mut self.rotors[k];
            r.net = if prescribed { 0.0 } else { r.torque - motor_friction(a, r.rate) };
            (self.modes[i], self.first[i]) = if prescribed {
                (PRESCRIBED, 0)
            } else {
                match self.held[i].unwrap_or_else(|| Band::of(a, r.rate)) {
                    Band::AtRest => (AT_REST, 2),
                    Band::Moving(s) => (MOVING, usize::from(r.net * s < 0.0)),
                }
            };
            self.ag[i * m..(i + 1) * m].copy_from_slice(&gu[k * m..(k + 1) * m]);
            let e = &self.e[i * m..(i + 1) * m];
            self.ae[i * m..(i + 1) * m].copy_from_slice(e);
        }
    }

    /// Motor i's side of its at-rest band: the held one, else qd's.
    fn side(&self, mech: &Mechanism, i: usize) -> Band {
        self.held[i].unwrap_or_else(|| Band::of(self.actuator(mech, i), self.rotors[self.slots[i]].rate))
    }

    /// Whether motor i's law has a side to hold: its coordinate was not following a prescribed
    /// motion at the last evaluation (a prescribed one's gear only reacts on its housing).
    pub(crate) fn free(&self, i: usize) -> bool {
        self.modes[i] != PRESCRIBED
    }

    /// Each motor's actuator index, side of its at-rest band (held or qd's), actuator and
    /// rate qd at the last evaluation.
    pub(crate) fn sides<'g, 'm: 'g>(
        &'g self,
        mech: &'m Mechanism,
    ) -> impl Iterator<Item = (usize, Band, &'m Actuator, f64)> + 'g {
        (0..self.slots.len()).map(move |i| {
            let k = self.slots[i];
            (k, self.side(mech, i), self.actuator(mech, i), self.rotors[k].rate)
        })
    }

    /// Hold motor i's side (`None`: choose it from qd at each evaluation).
    pub(crate) fn hold(&mut self, i: usize, side: Option<Band>) {
        self.held[i] = side;
    }

    /// The columns to solve with A (homogeneous: prescribed coordinates held), in place:
    /// g_i, and e_i where the housing moves (the others stay 0).
    pub(crate) fn columns(&mut self, m: usize) -> impl Iterator<Item = &mut [f64]> {
        let moving = self.ae.chunks_exact_mut(m.max(1)).zip(&self.housings).filter_map(|(c, h)| h.map(|_| c));
        self.ag.chunks_exact_mut(m.max(1)).chain(moving)
    }

    /// The products of the solved columns with g_i and w_i = n_i g_i + e_i.
    pub(crate) fn products(&mut self, mech: &Mechanism, gu: &[f64], m: usize) {
        let nm = self.slots.len();
        for i in 0..nm {
            let (g, e) = (&gu[self.slots[i] * m..(self.slots[i] + 1) * m], &self.e[i * m..(i + 1) * m]);
            let n = self.actuator(mech, i).ratio;
            for l in 0..nm {
                let (ag, ae) = (&self.ag[l * m..(l + 1) * m], &self.ae[l * m..(l + 1) * m]);
                (self.gg[i * nm + l], self.ge[i * nm + l]) = (dot(g, ag), dot(g, ae));
                self.wg[i * nm + l] = n * self.gg[i * nm + l] + dot(e, ag);
                self.we[i * nm + l] = n * self.ge[i * nm + l] + dot(e, ae);
            }
        }
    }

    /// rhs -= sum_i c_i e_i: the motors' net torques on their housings.
    pub(crate) fn housing_torques(&self, rhs: &mut [f64]) {
        let m = rhs.len();
        for (&k, e) in self.slots.iter().zip(self.e.chunks_exact(m.max(1))) {
            let c = self.rotors[k].net;
            rhs.iter_mut().zip(e).for_each(|(r, e)| *r -= c * e);
        }
    }

    /// The gears' modes and efforts for the accelerations `y0` = A^-1 (b - sum c_i e_i) without
    /// them (`gu` as in [`Gears::prepare`]); then rhs += sum_i (tau_i g_i + t_i e_i).
    pub(crate) fn solve(
        &mut self,
        mech: &Mechanism,
        y0: &[f64],
        gu: &[f64],
        rhs: &mut [f64],
    ) -> Result<(), KinematicsError> {
        let (m, nm) = (rhs.len(), self.slots.len());
        if nm == 0 {
            return Ok(());
        }
        for i in 0..nm {
            let (g, e) = (&gu[self.slots[i] * m..(self.slots[i] + 1) * m], &self.e[i * m..(i + 1) * m]);
            self.gy[i] = dot(g, y0);
            self.wy[i] = self.actuator(mech, i).ratio * self.gy[i] + dot(e, y0);
        }
        self.search(mech)?;
        for i in 0..nm {
            let k = self.slots[i];
            let (tau, t) = (self.u[i], self.u[nm + i]);
            (self.rotors[k].output, self.rotors[k].input) = (tau, t);
            let (g, e) = (&gu[k * m..(k + 1) * m], &self.e[i * m..(i + 1) * m]);
            rhs.iter_mut().zip(g.iter().zip(e)).for_each(|(r, (g, e))| *r += tau * g + t * e);
        }
        Ok(())
    }

    /// The choices of modes, the guess first (an odometer over each motor's candidates), until
    /// one's solution is in its branches.
    fn search(&mut self, mech: &Mechanism) -> Result<(), KinematicsError> {
        let nm = self.slots.len();
        self.digits.fill(0);
        loop {
            if self.try_modes(mech) && self.consistent(mech) {
                return Ok(());
            }
            let mut i = 0;
            loop {
                if i == nm {
                    let names = (0..nm).map(|i| self.actuator(mech, i).name.as_str()).collect::<Vec<_>>().join(", ");
                    return Err(KinematicsError::GearsJammed { actuators: names });
                }
                self.digits[i] += 1;
                if self.digits[i] < self.modes[i].len() {
                    break;
                }
                self.digits[i] = 0;
                i += 1;
            }
        }
    }

    fn mode(&self, i: usize) -> Mode {
        let c = self.modes[i];
        c[(self.first[i] + self.digits[i]) % c.len()]
    }

    /// Solve the current choice's system into `u`; false when it has no solution.
    fn try_modes(&mut self, mech: &Mechanism) -> bool {
        let nm = self.slots.len();
        let n2 = 2 * nm;
        self.k.fill(0.0);
        for i in 0..nm {
            let a = self.actuator(mech, i);
            let r = &self.rotors[self.slots[i]];
            let j = a.rotor_inertia;
            // The rotor's row.
            for l in 0..nm {
                self.k[i * n2 + l] = j * self.wg[i * nm + l];
                self.k[i * n2 + nm + l] = j * self.we[i * nm + l];
            }
            self.k[i * n2 + nm + i] += 1.0;
            self.u[i] = r.net - j * (r.r + self.wy[i]);
            // The gear's row.
            let row = (nm + i) * n2;
            self.u[nm + i] = 0.0;
            match self.mode(i) {
                Mode::Motoring => (self.k[row + i], self.k[row + nm + i]) = (1.0, -a.ratio * a.efficiency),
                Mode::BackDriven => (self.k[row + i], self.k[row + nm + i]) = (a.backdrive_efficiency, -a.ratio),
                Mode::Prescribed => self.k[row + i] = 1.0,
                Mode::Stuck => {
                    for l in 0..nm {
                        self.k[row + l] = self.gg[i * nm + l];
                        self.k[row + nm + l] = self.ge[i * nm + l];
                    }
                    self.u[nm + i] = -r.h - self.gy[i] - r.rate / STUCK_DECAY;
                }
            }
        }
        let scale = self.k.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        if lu_factor(&mut self.k, n2, &mut self.piv, PIVOT_TOL * scale).is_err() {
            return false;
        }
        lu_solve(&self.k, n2, &self.piv, &mut self.u);
        self.u.iter().all(|v| v.is_finite())
    }

    /// Whether the solution in `u` lies in each motor's branch (to [`MODE_TOL`]).
    fn consistent(&self, mech: &Mechanism) -> bool {
        let nm = self.slots.len();
        (0..nm).all(|i| {
            let a = self.actuator(mech, i);
            let r = &self.rotors[self.slots[i]];
            let (tau, t) = (self.u[i], self.u[nm + i]);
            let terms = (0..nm).map(|l| (self.gg[i * nm + l] * self.u[l], self.ge[i * nm + l] * self.u[nm + l]));
            let (qdd, size) = terms.fold((self.gy[i] + r.h, self.gy[i].abs() + r.h.abs()), |(s, z), (p, q)| {
                (s + p + q, z + p.abs() + q.abs())
            });
            let direction = self.side(mech, i).direction(r.rate, qdd);
            let direction =
                if direction.abs() > MODE_TOL * (size + (r.rate / STUCK_DECAY).abs()) { direction } else { 0.0 };
            let slack = MODE_TOL * (tau.abs() + a.ratio * (t.abs() + r.net.abs()));
            match self.mode(i) {
                Mode::Motoring => direction * tau >= -slack * direction.abs(),
                Mode::BackDriven => direction * tau <= slack * direction.abs(),
                Mode::Stuck => {
                    (tau - a.ratio * a.efficiency * t) * (a.backdrive_efficiency * tau - a.ratio * t) <= slack * slack
                }
                Mode::Prescribed => true,
            }
        })
    }

    /// After the solve of the final zdd: each motor's accelerations, its gear's output on the
    /// coordinate's effort `tau[k]` (the coordinates') and its forces on the bodies into `f`
    /// (tau_i along its lever `grad`, n_a x 3n; t_i - c_i on the housing's angle); returns their
    /// power (W).
    pub(crate) fn finish(
        &mut self,
        mech: &Mechanism,
        zdd: &[f64],
        gu: &[f64],
        grad: &[f64],
        tau: &mut [f64],
        f: &mut [f64],
    ) -> f64 {
        let (m, n) = (zdd.len(), f.len());
        let mut power = 0.0;
        for i in 0..self.slots.len() {
            let (k, ratio) = (self.slots[i], self.actuator(mech, i).ratio);
            let (g, e) = (&gu[k * m..(k + 1) * m], &self.e[i * m..(i + 1) * m]);
            let r = &mut self.rotors[k];
            let s = dot(g, zdd);
            r.accel = s + r.h;
            r.rotor_acc = ratio * s + dot(e, zdd) + r.r;
            f.iter_mut().zip(&grad[k * n..(k + 1) * n]).for_each(|(f, g)| *f += r.output * g);
            let reaction = r.input - r.net;
            if let Some(b) = self.housings[i] {
                f[3 * b + 2] += reaction;
            }
            if k < m {
                tau[k] = r.output;
            }
            power += r.output * r.rate + reaction * r.housing_rate;
        }
        power
    }

    /// Inverse dynamics at accelerations `qdd` (user chart; body accelerations `xdd`),
    /// after [`Gears::kinematics`]: each rotor's acceleration, and its reaction on its housing
    /// -J omega_r' into `f` (3n) and, through e_i, out of the efforts `tau` (m) the drives need.
    pub(crate) fn inverse(
        &mut self,
        mech: &Mechanism,
        xdd: &[f64],
        qdd: &[f64],
        gu: &[f64],
        tau: &mut [f64],
        f: &mut [f64],
    ) {
        let m = qdd.len();
        for i in 0..self.slots.len() {
            let (k, a) = (self.slots[i], self.actuator(mech, i));
            let r = &mut self.rotors[k];
            r.accel = if k < m { qdd[k] } else { dot(&gu[k * m..(k + 1) * m], qdd) + r.h };
            let housing_acc = self.housings[i].map_or(0.0, |b| xdd[3 * b + 2]);
            r.rotor_acc = a.ratio * r.accel + housing_acc;
            let reaction = -a.rotor_inertia * r.rotor_acc;
            if let Some(b) = self.housings[i] {
                f[3 * b + 2] += reaction;
                tau.iter_mut().zip(&self.e[i * m..(i + 1) * m]).for_each(|(t, e)| *t -= reaction * e);
            }
        }
    }

    /// Record the coordinates' joint-side efforts `tau` as their gears' outputs (inverse dynamics).
    pub(crate) fn set_outputs(&mut self, tau: &[f64]) {
        for &k in &self.slots {
            self.rotors[k].output = tau.get(k).copied().unwrap_or(0.0);
        }
    }
}
