// The channels a user can plot, made from a series of states (a run, or a sweep of one
// coordinate through evaluations): each {key, label, group, unit, values}. Groups as the
// viewer's: coordinates, rates, accelerations, efforts, energies, the singularity measure,
// pair reactions, point positions, speeds and accelerations.

export const GROUPS = [
  ["q", "coordinates"], ["qd", "rates"], ["qdd", "accelerations"], ["tau", "drive efforts"],
  ["energy", "energies"], ["sigma", "singularity measure"], ["reactions", "pair reactions"],
  ["positions", "point positions"], ["speeds", "point speeds"], ["point_accelerations", "point accelerations"],
];

/** An effort or energy channel whose largest magnitude is below this (N m, N or J) is all
 * zero: a passive model's efforts, a model's potential without gravity; not shown first. */
const ZERO_EFFORT = 1e-12;

const UNITS = {
  angle: { q: "rad", qd: "rad/s", qdd: "rad/s²", tau: "N m" },
  displacement: { q: "m", qd: "m/s", qdd: "m/s²", tau: "N" },
};

/** The unit of `quantity` (q, qd, qdd, tau) of coordinate k. */
export const unitOf = (info, k, quantity) => UNITS[info.coordinateKinds[k]][quantity];

/** Column k of an N x width row-major array. */
function column(a, width, k) {
  const n = a.length / width;
  const out = new Float64Array(n);
  for (let i = 0; i < n; i++) out[i] = a[i * width + k];
  return out;
}

/** |(a[i], a[i + 1])| for the pairs of columns (2k, 2k + 1) of an N x width array. */
function magnitude(a, width, k) {
  const n = a.length / width;
  const out = new Float64Array(n);
  for (let i = 0; i < n; i++) out[i] = Math.hypot(a[i * width + 2 * k], a[i * width + 2 * k + 1]);
  return out;
}

/** The channels of a series: `s` holds time-major arrays q, qd, qdd, tau (N x m), kinetic,
 * potential, sigma (N), optionally work (N), reactions (N x p x 3), points, pointVelocities,
 * pointAccelerations (N x P x 2); `info` is the mechanism's (`Mechanism.info()`). */
export function seriesChannels(info, s) {
  const m = info.dof;
  const chans = [];
  info.coordinateNames.forEach((name, k) => {
    for (const [g, prefix] of [["q", ""], ["qd", "qd_"], ["qdd", "qdd_"], ["tau", "tau_"]]) {
      if (s[g]) chans.push({ key: `${prefix}${name}`, label: `${prefix}${name}`, group: g, unit: unitOf(info, k, g), values: column(s[g], m, k) });
    }
  });
  const energy = [["kinetic", "T", s.kinetic], ["potential", "V", s.potential]];
  if (s.kinetic && s.potential) energy.push(["total", "T + V", s.kinetic.map((t, i) => t + s.potential[i])]);
  if (s.work) energy.push(["work", "W", s.work]);
  for (const [key, label, values] of energy) if (values) chans.push({ key, label, group: "energy", unit: "J", values });
  if (s.sigma) chans.push({ key: "sigma", label: "σ", group: "sigma", unit: "1", values: s.sigma });
  if (s.reactions) {
    const p = info.pairs.length;
    // Rows of p x 3 [F_x, F_y, M]: the force's magnitude is that of columns 3j, 3j + 1.
    const forces = (j) => { const n = s.reactions.length / (3 * p), out = new Float64Array(n); for (let i = 0; i < n; i++) out[i] = Math.hypot(s.reactions[(i * p + j) * 3], s.reactions[(i * p + j) * 3 + 1]); return out; };
    info.pairs.forEach((pair, j) => chans.push({ key: `F_${pair.name}`, label: `|F| ${pair.name}`, group: "reactions", unit: "N", values: forces(j) }));
  }
  const P = info.points.length;
  info.points.forEach((name, k) => {
    if (s.points) {
      chans.push({ key: `x_${name}`, label: `x ${name}`, group: "positions", unit: "m", values: column(s.points, 2 * P, 2 * k) });
      chans.push({ key: `y_${name}`, label: `y ${name}`, group: "positions", unit: "m", values: column(s.points, 2 * P, 2 * k + 1) });
    }
    if (s.pointVelocities) chans.push({ key: `v_${name}`, label: `|v| ${name}`, group: "speeds", unit: "m/s", values: magnitude(s.pointVelocities, 2 * P, k) });
    if (s.pointAccelerations) chans.push({ key: `a_${name}`, label: `|a| ${name}`, group: "point_accelerations", unit: "m/s²", values: magnitude(s.pointAccelerations, 2 * P, k) });
  });
  return chans;
}

/** Whether a channel is not all zero (within ZERO_EFFORT). */
const nonZero = (c) => c.values.some((v) => Math.abs(v) > ZERO_EFFORT);

/** The channels shown first: the coordinates with the efforts that are not all zero, else
 * with the energies that are not (a passive model's efforts are all zero), else with the
 * singularity measure (at rest without gravity, efforts and energies are all zero). */
export function defaultChannels(chans) {
  const q = chans.filter((c) => c.group === "q");
  const efforts = chans.filter((c) => c.group === "tau" && nonZero(c));
  const energies = chans.filter((c) => ["total", "kinetic", "potential"].includes(c.key) && nonZero(c));
  const second = efforts.length ? efforts : energies.length ? energies : chans.filter((c) => c.group === "sigma");
  return new Set([...q, ...second].map((c) => c.key));
}

/** CSV text: the x axis (label with unit) then every channel, one row per state. */
export function toCsv(xLabel, x, chans) {
  const head = [xLabel, ...chans.map((c) => `${c.label} (${c.unit})`)].map((h) => `"${h.replace(/"/g, '""')}"`);
  const lines = [head.join(",")];
  for (let i = 0; i < x.length; i++) lines.push([x[i], ...chans.map((c) => c.values[i])].map((v) => (Number.isFinite(v) ? String(v) : "")).join(","));
  return lines.join("\n") + "\n";
}
