// A run made in Python, in the data format of planardyn's HTML viewer (`viewer_data`:
// point positions per frame P, bodies and ground as point indices, each pair's drawing per
// frame, channels with their units), played without the engine.

import { defaultChannels } from "./channels.js";

/** Whether parsed JSON is a viewer's data. */
export const isRun = (d) => d && Array.isArray(d.P) && Array.isArray(d.t) && Array.isArray(d.channels);

const f64 = (a) => Float64Array.from(a, (v) => (v === null ? NaN : v));

/** The run's times and channels as the charts take them. */
export function replaySeries(data) {
  const chans = data.channels.map((c) => ({ key: c.key, label: c.label, group: c.group, unit: c.unit, values: f64(c.values), on: c.on }));
  return { data, t: f64(data.t), chans };
}

/** The channels a run opens on: those its data marks `on` (channels chosen in Python), else
 * the ones the page opens its own runs on. */
export function replayDefaults(chans) {
  const marked = chans.filter((c) => c.on !== undefined);
  return marked.length ? new Set(marked.filter((c) => c.on).map((c) => c.key)) : defaultChannels(chans);
}

/** The scene of frame i, traced points' paths up to it. */
export function replayScene(replay, i) {
  const d = replay.data;
  const geometry = d.joints.map((j) => ({
    name: j.name, kind: j.kind,
    pins: f64(j.pins[i]), blocks: f64(j.blocks[i]), lines: f64(j.lines[i]), circles: f64(j.circles[i]),
  }));
  const paths = d.traces.map((p) => f64(d.P.slice(0, i + 1).flatMap((row) => [row[2 * p], row[2 * p + 1]])));
  return { points: f64(d.P[i]), bodies: d.bodies.map((b) => b.pts), ground: d.ground, geometry, arrows: null, paths, scale: d.scale };
}
