//! Dormand-Prince 8(5,3): explicit Runge-Kutta of order 8 with Hairer's
//! combined 5th/3rd-order error estimator and a dense output of order 7.
//!
//! References: P. J. Prince, J. R. Dormand, "High order embedded Runge-Kutta
//! formulae", J. Comput. Appl. Math. 7 (1981) 67-75; HNW I, II.5 and II.6
//! (dense output) and Hairer's Fortran code DOP853. The coefficients are those
//! of DOP853, as tabulated in scipy's `integrate/_ivp/dop853_coefficients.py`
//! (30 significant digits, rounded here to `f64`); the unit test at the end
//! checks the order conditions they must satisfy.
//!
//! Stages: 12 for the step, the 13th is `f(t + h, y_new)` (FSAL, reused as the
//! next step's first stage), so a step costs 12 `rhs` calls. Error estimate
//! (HNW I, p. 254): with `e5 = h sum E5_j K_j`, `e3 = h sum E3_j K_j` scaled by
//! `sc`, `err = |e5|^2 / sqrt(n (|e5|^2 + 0.01 |e3|^2))` (RMS, as 5th order
//! for large steps, behaving like order 8 asymptotically); the controller uses
//! exponent `-1/8`. A step whose 3rd-order estimate is large against its own increment
//! reaches too near a singularity of the solution for that estimate to hold: its error is
//! raised so that the step shrinks ([`REACH_E3`]).
//!
//! Dense output: 3 more stages (`C = 0.1, 0.2, 7/9`), evaluated lazily by the
//! first [`interpolate`](Dop853::interpolate) within an accepted step, so a step
//! with no output time in it costs 12 `rhs` calls and one with outputs 15. Set
//! [`Options::dense_output`] to `false` to skip them: the interpolant then
//! degrades to the cubic Hermite polynomial (order 3). If one of the extra
//! stages fails, that step's solution at a time inside it is a step of the method from
//! the step's start to that time (12 more evaluations, and as accurate as the step), or,
//! if one of those fails too, the cubic Hermite polynomial. The first step after a reset is
//! interpolated as any other: where its starting guess may be far too long (after a chart
//! switch), the system bounds it (`Stepper::bound_first_step`).

// The coefficients keep the 30 digits of the published table, so that they can be
// compared with it digit by digit; the compiler rounds them to f64.
#![allow(clippy::excessive_precision)]

use super::control::{all_finite, combine, explicit_step, scaled_sum, weighted_sum, Core, ExplicitPair, Failure};
use super::{Integrator, OdeSystem, Options, StepError};
use crate::linalg::copy_small;

/// Stages of the step (the FSAL stage excluded).
const N_STAGES: usize = 12;
/// All stages: the step's 12, the FSAL stage, the 3 dense-output stages.
const N_EXT: usize = 16;

const C: [f64; N_EXT] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777777777777777777777777777778,
];

/// Runge-Kutta matrix, zero-padded; row 12 is the weight vector `B`.
#[rustfmt::skip]
const A: [[f64; 15]; N_EXT] = {
    let mut a = [[0.0; 15]; N_EXT];
    a[1][0] = 5.26001519587677318785587544488e-2;

    a[2][0] = 1.97250569845378994544595329183e-2;
    a[2][1] = 5.91751709536136983633785987549e-2;

    a[3][0] = 2.95875854768068491816892993775e-2;
    a[3][2] = 8.87627564304205475450678981324e-2;

    a[4][0] = 2.41365134159266685502369798665e-1;
    a[4][2] = -8.84549479328286085344864962717e-1;
    a[4][3] = 9.24834003261792003115737966543e-1;

    a[5][0] = 3.7037037037037037037037037037e-2;
    a[5][3] = 1.70828608729473871279604482173e-1;
    a[5][4] = 1.25467687566822425016691814123e-1;

    a[6][0] = 3.7109375e-2;
    a[6][3] = 1.70252211019544039314978060272e-1;
    a[6][4] = 6.02165389804559606850219397283e-2;
    a[6][5] = -1.7578125e-2;

    a[7][0] = 3.70920001185047927108779319836e-2;
    a[7][3] = 1.70383925712239993810214054705e-1;
    a[7][4] = 1.07262030446373284651809199168e-1;
    a[7][5] = -1.53194377486244017527936158236e-2;
    a[7][6] = 8.27378916381402288758473766002e-3;

    a[8][0] = 6.24110958716075717114429577812e-1;
    a[8][3] = -3.36089262944694129406857109825;
    a[8][4] = -8.68219346841726006818189891453e-1;
    a[8][5] = 2.75920996994467083049415600797e1;
    a[8][6] = 2.01540675504778934086186788979e1;
    a[8][7] = -4.34898841810699588477366255144e1;

    a[9][0] = 4.77662536438264365890433908527e-1;
    a[9][3] = -2.48811461997166764192642586468;
    a[9][4] = -5.90290826836842996371446475743e-1;
    a[9][5] = 2.12300514481811942347288949897e1;
    a[9][6] = 1.52792336328824235832596922938e1;
    a[9][7] = -3.32882109689848629194453265587e1;
    a[9][8] = -2.03312017085086261358222928593e-2;

    a[10][0] = -9.3714243008598732571704021658e-1;
    a[10][3] = 5.18637242884406370830023853209;
    a[10][4] = 1.09143734899672957818500254654;
    a[10][5] = -8.14978701074692612513997267357;
    a[10][6] = -1.85200656599969598641566180701e1;
    a[10][7] = 2.27394870993505042818970056734e1;
    a[10][8] = 2.49360555267965238987089396762;
    a[10][9] = -3.0467644718982195003823669022;

    a[11][0] = 2.27331014751653820792359768449;
    a[11][3] = -1.05344954667372501984066689879e1;
    a[11][4] = -2.00087205822486249909675718444;
    a[11][5] = -1.79589318631187989172765950534e1;
    a[11][6] = 2.79488845294199600508499808837e1;
    a[11][7] = -2.85899827713502369474065508674;
    a[11][8] = -8.87285693353062954433549289258;
    a[11][9] = 1.23605671757943030647266201528e1;
    a[11][10] = 6.43392746015763530355970484046e-1;

    a[12][0] = 5.42937341165687622380535766363e-2;
    a[12][5] = 4.45031289275240888144113950566;
    a[12][6] = 1.89151789931450038304281599044;
    a[12][7] = -5.8012039600105847814672114227;
    a[12][8] = 3.1116436695781989440891606237e-1;
    a[12][9] = -1.52160949662516078556178806805e-1;
    a[12][10] = 2.01365400804030348374776537501e-1;
    a[12][11] = 4.47106157277725905176885569043e-2;

    a[13][0] = 5.61675022830479523392909219681e-2;
    a[13][6] = 2.53500210216624811088794765333e-1;
    a[13][7] = -2.46239037470802489917441475441e-1;
    a[13][8] = -1.24191423263816360469010140626e-1;
    a[13][9] = 1.5329179827876569731206322685e-1;
    a[13][10] = 8.20105229563468988491666602057e-3;
    a[13][11] = 7.56789766054569976138603589584e-3;
    a[13][12] = -8.298e-3;

    a[14][0] = 3.18346481635021405060768473261e-2;
    a[14][5] = 2.83009096723667755288322961402e-2;
    a[14][6] = 5.35419883074385676223797384372e-2;
    a[14][7] = -5.49237485713909884646569340306e-2;
    a[14][10] = -1.08347328697249322858509316994e-4;
    a[14][11] = 3.82571090835658412954920192323e-4;
    a[14][12] = -3.40465008687404560802977114492e-4;
    a[14][13] = 1.41312443674632500278074618366e-1;

    a[15][0] = -4.28896301583791923408573538692e-1;
    a[15][5] = -4.69762141536116384314449447206;
    a[15][6] = 7.68342119606259904184240953878;
    a[15][7] = 4.06898981839711007970213554331;
    a[15][8] = 3.56727187455281109270669543021e-1;
    a[15][12] = -1.39902416515901462129418009734e-3;
    a[15][13] = 2.9475147891527723389556272149;
    a[15][14] = -9.15095847217987001081870187138;
    a
};

/// Weights of the 8th-order solution.
const B: [f64; N_STAGES] = {
    let mut b = [0.0; N_STAGES];
    let mut j = 0;
    while j < N_STAGES {
        b[j] = A[12][j];
        j += 1;
    }
    b
};

/// 3rd-order error weights `B - BHH` (13 entries, the FSAL stage has weight 0).
const E3: [f64; N_STAGES + 1] = {
    let mut e = [0.0; N_STAGES + 1];
    let mut j = 0;
    while j < N_STAGES {
        e[j] = B[j];
        j += 1;
    }
    e[0] -= 0.244094488188976377952755905512;
    e[8] -= 0.733846688281611857341361741547;
    e[11] -= 0.220588235294117647058823529412e-1;
    e
};

/// 5th-order error weights (13 entries).
const E5: [f64; N_STAGES + 1] = [
    0.1312004499419488073250102996e-1,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.1225156446376204440720569753e1,
    -0.4957589496572501915214079952,
    0.1664377182454986536961530415e1,
    -0.3503288487499736816886487290,
    0.3341791187130174790297318841,
    0.8192320648511571246570742613e-1,
    -0.2235530786388629525884427845e-1,
    0.0,
];

/// Dense output: rows 3..6 of the interpolant's coefficients, `h D K` (4 x 16).
#[rustfmt::skip]
const D: [[f64; N_EXT]; 4] = [
    [
        -0.84289382761090128651353491142e1, 0.0, 0.0, 0.0, 0.0,
        0.56671495351937776962531783590, -0.30689499459498916912797304727e1,
        0.23846676565120698287728149680e1, 0.21170345824450282767155149946e1,
        -0.87139158377797299206789907490, 0.22404374302607882758541771650e1,
        0.63157877876946881815570249290, -0.88990336451333310820698117400e-1,
        0.18148505520854727256656404962e2, -0.91946323924783554000451984436e1,
        -0.44360363875948939664310572000e1,
    ],
    [
        0.10427508642579134603413151009e2, 0.0, 0.0, 0.0, 0.0,
        0.24228349177525818288430175319e3, 0.16520045171727028198505394887e3,
        -0.37454675472269020279518312152e3, -0.22113666853125306036270938578e2,
        0.77334326684722638389603898808e1, -0.30674084731089398182061213626e2,
        -0.93321305264302278729567221706e1, 0.15697238121770843886131091075e2,
        -0.31139403219565177677282850411e2, -0.93529243588444783865713862664e1,
        0.35816841486394083752465898540e2,
    ],
    [
        0.19985053242002433820987653617e2, 0.0, 0.0, 0.0, 0.0,
        -0.38703730874935176555105901742e3, -0.18917813819516756882830838328e3,
        0.52780815920542364900561016686e3, -0.11573902539959630126141871134e2,
        0.68812326946963000169666922661e1, -0.10006050966910838403183860980e1,
        0.77771377980534432092869265740, -0.27782057523535084065932004339e1,
        -0.60196695231264120758267380846e2, 0.84320405506677161018159903784e2,
        0.11992291136182789328035130030e2,
    ],
    [
        -0.25693933462703749003312586129e2, 0.0, 0.0, 0.0, 0.0,
        -0.15418974869023643374053993627e3, -0.23152937917604549567536039109e3,
        0.35763911791061412378285349910e3, 0.93405324183624310003907691704e2,
        -0.37458323136451633156875139351e2, 0.10409964950896230045147246184e3,
        0.29840293426660503123344363579e2, -0.43533456590011143754432175058e2,
        0.96324553959188282948394950600e2, -0.39177261675615439165231486172e2,
        -0.14972683625798562581422125276e3,
    ],
];

/// Largest ratio `|e3| / |y_new - y|` (scaled RMS norms) at which Hairer's combined estimate is
/// trusted: the 3rd-order estimate against the step's own increment, a scale-free measure of
/// how far the step reaches towards the nearest (complex) singularity of the solution, at
/// distance R. For a singularity's Taylor series the ratio grows like (h/R)^3; one step of
/// this pair gives 0.027 at h/R = 0.5 for a pole (y' = y^2), 0.0071 for a logarithm
/// (y' = 1/(1-t)), 0.001-0.002 for a complex pair (y' = 1/(1+t^2)), and 0.01 at about
/// h/R = 0.36 (pole), 0.5 (logarithm), 0.8 (complex pair). Beyond that reach the combined
/// estimate `e5^2 / sqrt(e5^2 + 0.01 e3^2)` is no longer an error bound: e5 can be small by
/// accident and a huge e3 deflates it further (the Scotch yoke's crank whipping through
/// theta = 0 mod pi, complex singularities 3 ms away: steps of 15-17 ms with e5 = 22, e3 = 6500
/// tolerances, estimate 0.77, true error 143 tolerances). Over rtol = atol = 10^(-k/20),
/// k = 20..200, 1 s (benchmarks/drift_outliers.py), the tolerances whose energy drift is over
/// 10x the geometric mean of their neighbours' go from 17 to 0 on the yoke (over 5x: 26 -> 1),
/// at +20 % evaluations; 76 -> 54 over 11 models (+7.7 %; the five-bar robot, whose friction
/// and gear efficiency switch, 17 -> 24). In a replica (scipy's DOP853 on the yoke's
/// equations written out, without the gate) 0.03 leaves 2 over 10x, 0.003 none, for +33 %
/// evaluations at k >= 60.
const REACH_E3: f64 = 0.01;

/// The error norm that keeps a step within [`REACH_E3`]: `(eta / REACH_E3)^(8/3)` with
/// `eta = |e3| / |dy|`, which scales like h^8 as the controller's error does (exponent 1/8), so
/// that a rejected step shrinks to the reach at once; 0 where the 3rd-order solution is within
/// the tolerance (`e3 <= 1`, scaled RMS). That gate ends the rejections where eta does not fall
/// with h: across a jump of the right-hand side (friction, a limit) e3 and dy both fall like h.
/// A step that does not move at all (dy = 0) gets e3 itself.
fn reach_error(e3: f64, dy: f64) -> f64 {
    if e3 <= 1.0 || e3 <= REACH_E3 * dy {
        0.0
    } else if dy == 0.0 {
        e3
    } else {
        // Capped: a step that barely moves (dy below ~1e-113 tolerances) would overflow.
        (e3 / (REACH_E3 * dy)).powf(8.0 / 3.0).min(f64::MAX)
    }
}

/// DOP853 stepper. All buffers allocated in `new`.
pub struct Dop853 {
    pub(crate) core: Core,
    /// Stages `K_0..K_15`, stage-major (`16 x n`).
    k: Vec<f64>,
    /// Dense output coefficients `F_0..F_6` of the last accepted step (`7 x n`).
    fd: Vec<f64>,
    ytmp: Vec<f64>,
    /// The 3rd-order error estimate of the last attempt (`ytmp` holds the 5th-order one).
    e3: Vec<f64>,
    y_new: Vec<f64>,
    f_new: Vec<f64>,
    /// Step size of the last attempt (s).
    h: f64,
    /// Whether `fd` holds the 7th-order coefficients of the last accepted step (else only
    /// its cubic Hermite rows, until the next `interpolate` evaluates the extra stages).
    dense_ready: bool,
    /// Whether an extra stage of the last accepted step failed: `interpolate` then steps from
    /// its start instead ([`Dop853::substep`]).
    substep: bool,
}

impl Integrator for Dop853 {
    const NAME: &'static str = "dop853";
    const ALIASES: &'static [&'static str] = &[];
    const ORDER: usize = 8;
    /// Degree 7 (with `Options::dense_output`; cubic Hermite without).
    const DENSE_ORDER: usize = 7;
    const ADAPTIVE: bool = true;
    const IMPLICIT: bool = false;
    /// Its reach term ([`REACH_E3`]).
    const SEES_REACH: bool = true;

    fn new(opts: &Options, n: usize) -> Self {
        Dop853 {
            core: Core::new(opts, n),
            k: vec![0.0; N_EXT * n],
            fd: vec![0.0; 7 * n],
            ytmp: vec![0.0; n],
            e3: vec![0.0; n],
            y_new: vec![0.0; n],
            f_new: vec![0.0; n],
            h: 0.0,
            dense_ready: true,
            substep: false,
        }
    }

    /// 7th-order dense output on the last accepted step (HNW I, II.6; scipy
    /// `Dop853DenseOutput`): with `s = (t - t_prev)/h`,
    /// `y = y_prev + s (F0 + (1-s) (F1 + s (F2 + (1-s) (F3 + s (F4 + (1-s) (F5 + s F6))))))`.
    /// The first call within a step evaluates its 3 extra stages with `sys`; if one fails, a
    /// time inside the step is reached by a step from its start ([`Dop853::substep`]).
    fn interpolate<S: OdeSystem>(&mut self, sys: &mut S, t: f64, out: &mut [f64]) {
        if !self.dense_ready {
            self.dense_coefficients(sys);
        }
        let h = self.core.t - self.core.t_prev;
        let s = if h == 0.0 { 0.0 } else { (t - self.core.t_prev) / h };
        if self.substep && s > 0.0 && s < 1.0 && self.substep(sys, s * h, out).is_ok() {
            return;
        }
        let (c, n, s1) = (&self.core, self.core.n, 1.0 - s);
        let f = |r: usize| &self.fd[r * n..(r + 1) * n];
        let rows = f(0).iter().zip(f(1)).zip(f(2)).zip(f(3)).zip(f(4)).zip(f(5)).zip(f(6));
        for ((((((((f0, f1), f2), f3), f4), f5), f6), y), o) in rows.zip(&c.y_prev).zip(out.iter_mut()) {
            *o = y + (f0 + (f1 + (f2 + (f3 + (f4 + (f5 + f6 * s) * s1) * s) * s1) * s) * s1) * s;
        }
    }
}

impl Dop853 {
    pub fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), StepError<S::Error>> {
        self.fd.fill(0.0);
        self.dense_ready = true;
        self.substep = false;
        self.core.reset(sys, t, y)
    }

    pub fn step<S: OdeSystem>(&mut self, sys: &mut S, t_stop: f64) -> Result<(), StepError<S::Error>> {
        explicit_step(self, sys, t_stop)
    }

    /// Rows 3..6 of the dense output of the last accepted step, from its stages and the 3
    /// extra ones (evaluated from its start point, now `y_prev`); zero (cubic Hermite) if
    /// dense output is off or an extra stage fails.
    fn dense_coefficients<S: OdeSystem>(&mut self, sys: &mut S) {
        self.dense_ready = true;
        let (n, h) = (self.core.n, self.h);
        let mut extra_ok = self.core.opts.dense_output;
        if extra_ok {
            for s in N_STAGES + 1..N_EXT {
                if self.stage(sys, s, h, true).is_err() {
                    extra_ok = false;
                    break;
                }
            }
        }
        self.substep = self.core.opts.dense_output && !extra_ok;
        let Dop853 { k, fd, .. } = self;
        for (r, row) in fd[3 * n..].chunks_exact_mut(n.max(1)).enumerate() {
            if extra_ok {
                scaled_sum(row, h, &D[r], k);
            } else {
                row.fill(0.0);
            }
        }
    }

    /// The solution at `t_prev + hs` (0 < hs < h) by one step of the method from the start of
    /// the last accepted step, into `out`: where an extra stage failed (a stage point near a
    /// singularity of the system that the step's own stages passed between, see
    /// `simulate::ode`), the cubic Hermite polynomial would be the only other answer, and it is
    /// of order 3 (the five-bar at rtol 1.26e-7: an output 1.4e-5 J off, where the steps are
    /// 4.6e-7 J). Overwrites the step's stages 1..11 (its dense output no longer needs them;
    /// stage 0 is f at the start, as for the step).
    fn substep<S: OdeSystem>(&mut self, sys: &mut S, hs: f64, out: &mut [f64]) -> Result<(), Failure<S::Error>> {
        for s in 1..N_STAGES {
            self.stage(sys, s, hs, true)?;
        }
        let Dop853 { core, k, .. } = self;
        combine(out, &core.y_prev, hs, &B, &k[..N_STAGES * core.n]);
        if all_finite(out) {
            Ok(())
        } else {
            Err(Failure::NonFinite)
        }
    }

    /// Evaluate stage `s` from the stages before it: `K_s = f(t + C_s h, y + h sum_j A_sj K_j)`,
    /// from the current point, or (`accepted`) from the start of the last accepted step.
    /// Inlined: as a call of its own each of a step's 11 stages saved and restored its
    /// registers and checked its slices' bounds again (four-bar 10 s, 4634 stages: 12.57 M ->
    /// 12.40 M instructions a run).
    #[inline(always)]
    fn stage<S: OdeSystem>(&mut self, sys: &mut S, s: usize, h: f64, accepted: bool) -> Result<(), Failure<S::Error>> {
        let Dop853 { core, k, ytmp, .. } = self;
        let n = core.n;
        let (t0, y0) = if accepted { (core.t_prev, &core.y_prev) } else { (core.t, &core.y) };
        combine(ytmp, y0, h, &A[s][..s], &k[..s * n]);
        let ks = &mut k[s * n..(s + 1) * n];
        if accepted {
            Core::eval_dense(&mut core.stats, sys, t0 + C[s] * h, ytmp, ks)
        } else {
            Core::eval(&mut core.stats, sys, t0 + C[s] * h, ytmp, ks)
        }
    }

    /// Stage `I` of an attempt ([`Dop853::stage`] from the current point). With `I` a constant
    /// the row `A[I]` is known where its sum is inlined (`combine`), so the compiler drops its
    /// zero weights and unrolls the rest: the four-bar's 10 s run (4634 stages) 12.40 M ->
    /// 12.07 M instructions, where a loop over the stages, even unrolled, kept a test and a
    /// branch for each weight (12.29 M).
    #[inline(always)]
    fn stage_at<const I: usize, S: OdeSystem>(&mut self, sys: &mut S, h: f64) -> Result<(), Failure<S::Error>> {
        self.stage(sys, I, h, false)
    }
}

impl ExplicitPair for Dop853 {
    const ERROR_ORDER: usize = 7;

    fn core(&mut self) -> &mut Core {
        &mut self.core
    }

    fn scratch(&mut self) -> (&mut Core, &mut [f64], &mut [f64]) {
        (&mut self.core, &mut self.ytmp, &mut self.f_new)
    }

    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, h: f64) -> Result<f64, Failure<S::Error>> {
        let n = self.core.n;
        if !self.dense_ready {
            // The stages of the last accepted step are about to be overwritten: its dense
            // output, if ever asked for, falls back to cubic Hermite.
            self.fd[3 * n..].fill(0.0);
            self.dense_ready = true;
        }
        self.h = h;
        copy_small(&mut self.k[..n], &self.core.f);
        // Stage by stage with the index a constant: each stage's sum is then of its tableau
        // row's nonzero weights only, unrolled, with no test of a weight (see `stage_at`).
        macro_rules! stages {
            ($($s:literal)*) => { $(self.stage_at::<$s, S>(sys, h)?;)* };
        }
        const { assert!(N_STAGES == 12, "the stages listed are 1..N_STAGES") };
        stages!(1 2 3 4 5 6 7 8 9 10 11);
        let Dop853 { core, k, ytmp, e3, y_new, f_new, .. } = self;
        combine(y_new, &core.y, h, &B, &k[..N_STAGES * n]);
        if !all_finite(y_new) {
            return Err(Failure::NonFinite);
        }
        Core::eval(&mut core.stats, sys, core.t + h, y_new, f_new)?;
        copy_small(&mut k[N_STAGES * n..(N_STAGES + 1) * n], f_new);
        // Hairer's combined estimator, in scaled RMS form, and the step's increment in the same
        // scale (for `reach_error`).
        let e5 = ytmp;
        weighted_sum(e5, &E5, k);
        weighted_sum(e3, &E3, k);
        let (mut e5sq, mut e3sq, mut dysq) = (0.0, 0.0, 0.0);
        for (((e5, e3), y), y_new) in e5.iter().zip(e3.iter()).zip(&core.y).zip(y_new.iter()) {
            let sc = core.opts.atol + core.opts.rtol * y.abs().max(y_new.abs());
            e5sq += (e5 / sc).powi(2);
            e3sq += (e3 / sc).powi(2);
            dysq += ((y_new - y) / sc).powi(2);
        }
        if e5sq == 0.0 && e3sq == 0.0 {
            return Ok(0.0);
        }
        let denom = e5sq + 0.01 * e3sq;
        let combined = h.abs() * e5sq / (denom * n as f64).sqrt();
        let e3 = h.abs() * (e3sq / n as f64).sqrt();
        Ok(combined.max(reach_error(e3, (dysq / n as f64).sqrt())))
    }

    /// The cubic Hermite rows of the dense output now; rows 3..6 when first interpolated.
    fn accept<S: OdeSystem>(&mut self, _sys: &mut S, t_new: f64) {
        let (n, h) = (self.core.n, self.h);
        let Dop853 { core, fd, y_new, f_new, .. } = self;
        for i in 0..n {
            let dy = y_new[i] - core.y[i];
            fd[i] = dy;
            fd[n + i] = h * core.f[i] - dy;
            fd[2 * n + i] = 2.0 * dy - h * (f_new[i] + core.f[i]);
        }
        self.dense_ready = false;
        self.substep = false;
        self.core.accept(t_new, &mut self.y_new, &mut self.f_new);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Row sums of A equal C; B satisfies the quadrature conditions
    /// `sum_j B_j C_j^q = 1/(q+1)` for q = 0..7; the error weights sum to 0.
    #[test]
    fn coefficients_satisfy_order_conditions() {
        for (s, row) in A.iter().enumerate() {
            let sum: f64 = row.iter().sum();
            assert!((sum - C[s]).abs() < 1e-14, "row {s}: {sum} vs {}", C[s]);
        }
        for q in 0..8 {
            let sum: f64 = (0..N_STAGES).map(|j| B[j] * C[j].powi(q)).sum();
            assert!((sum - 1.0 / (q as f64 + 1.0)).abs() < 1e-14, "q = {q}: {sum}");
        }
        // The 5th-order embedded solution (B - E5) also integrates c^q exactly, q < 5.
        for q in 0..5 {
            let sum: f64 = (0..=N_STAGES).map(|j| (B.get(j).unwrap_or(&0.0) - E5[j]) * C[j].powi(q)).sum();
            assert!((sum - 1.0 / (q as f64 + 1.0)).abs() < 1e-13, "E5, q = {q}: {sum}");
        }
        assert!(E3.iter().sum::<f64>().abs() < 1e-14);
        assert!(E5.iter().sum::<f64>().abs() < 1e-14);
    }
}
