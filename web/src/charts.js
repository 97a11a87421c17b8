// Charts of the chosen channels with uPlot: one chart per unit (so every axis has one unit
// and nice-number ticks), sharing the x axis and the cursor, with a marker at the current
// state; a click moves the state there. The chooser lists every channel by group.
import uPlot from "uplot";
import { GROUPS } from "./channels.js";

const COLORS = ["#1f6fb2", "#d9730d", "#2e8540", "#8e44ad", "#b3261e", "#0f7c80", "#7a5c00", "#c2185b"];
/** Height of one chart (px, its plot and x axis): the charts share the area, scrolling below
 * MIN_HEIGHT, whose plot (100 px, less the axis) still holds four ticks Y_TICK_SPACE apart. */
const MIN_HEIGHT = 130;
const MAX_HEIGHT = 320;
/** The legend's line under each chart (px, as chromium lays it out, with its 2 px margin). */
const LEGEND_HEIGHT = 27;
/** The x axis's tick labels (px), and its label's line under the last chart. */
const X_AXIS_SIZE = 30;
const X_LABEL_SIZE = 20;
/** Least distance between y ticks (px; uPlot's default, 30, left charts of 150 px one tick). */
const Y_TICK_SPACE = 22;
/** The charts' area's padding (px, top and bottom: app.css's 4 px each). */
const AREA_PAD = 8;
/** Charts the area holds whole at least (a model's default channels span at most two units):
 * the page gives the area their height and its 1 px top border (app.css's --charts-min) before
 * the drawing its share. */
const CHARTS_SHOWN = 2;

/** uPlot's range with a margin, never below zero for a channel that never is (|F|, speeds). */
function range(u, min, max) {
  if (min === max) return [min - 1, max + 1];
  const [a, b] = uPlot.rangeNum(min, max, 0.1, true);
  return [min >= 0 ? Math.max(0, a) : a, b];
}

export class Charts {
  constructor(chooser, area, onPick) {
    this.chooser = chooser;
    this.area = area;
    this.onPick = onPick;
    this.plots = [];
    this.chans = [];
    this.on = new Set();
    this.x = new Float64Array(0);
    this.xLabel = "";
    this.marker = null;
    /** Whether the user has chosen channels (then kept across series). */
    this.chosen = false;
    document.documentElement.style.setProperty("--charts-min", `${CHARTS_SHOWN * (MIN_HEIGHT + LEGEND_HEIGHT) + X_LABEL_SIZE + AREA_PAD + 1}px`);
  }

  /** Show channels `chans` over `x` (label with unit), keeping the channels the user chose
   * where they still name channels, else `defaults` (the defaults of the series shown before
   * are not kept: a sweep's holding efforts are a passive model's zero efforts in its run). */
  set(x, xLabel, chans, defaults) {
    const keys = new Set(chans.map((c) => c.key));
    const kept = this.chosen ? [...this.on].filter((k) => keys.has(k)) : [];
    this.on = kept.length ? new Set(kept) : defaults;
    Object.assign(this, { x, xLabel, chans });
    this.renderChooser();
    this.render();
  }

  renderChooser() {
    this.chooser.replaceChildren();
    for (const [g, label] of GROUPS) {
      const members = this.chans.filter((c) => c.group === g);
      if (!members.length) continue;
      const box = document.createElement("details");
      box.open = members.some((c) => this.on.has(c.key));
      const sum = document.createElement("summary");
      sum.textContent = `${label} (${members[0].unit})`;
      box.append(sum);
      for (const c of members) {
        const row = document.createElement("label");
        const input = document.createElement("input");
        input.type = "checkbox";
        input.checked = this.on.has(c.key);
        input.dataset.key = c.key;
        input.addEventListener("change", () => {
          this.chosen = true;
          input.checked ? this.on.add(c.key) : this.on.delete(c.key);
          this.render();
        });
        row.append(input, ` ${c.label}`);
        box.append(row);
      }
      this.chooser.append(box);
    }
  }

  render() {
    for (const p of this.plots) p.destroy();
    this.plots = [];
    this.area.replaceChildren();
    const chosen = this.chans.filter((c) => this.on.has(c.key));
    const units = [...new Set(chosen.map((c) => c.unit))];
    const width = Math.max(200, this.area.clientWidth - 12);
    const height = Math.min(MAX_HEIGHT, Math.max(MIN_HEIGHT, (this.area.clientHeight - AREA_PAD - X_LABEL_SIZE) / Math.max(1, units.length) - LEGEND_HEIGHT));
    const sync = uPlot.sync("planardyn");
    units.forEach((unit, u) => {
      const members = chosen.filter((c) => c.unit === unit);
      // The x axis's label under the last chart only (uPlot keeps a label's room even when empty).
      const last = u === units.length - 1;
      const opts = {
        width, height: height + (last ? X_LABEL_SIZE : 0),
        scales: { x: { time: false }, y: { range } },
        axes: [{ size: X_AXIS_SIZE, ...(last ? { label: this.xLabel, labelSize: X_LABEL_SIZE } : {}) },
          { label: unit, size: 60, labelSize: X_LABEL_SIZE, space: Y_TICK_SPACE }],
        series: [{ label: this.xLabel }, ...members.map((c, i) => ({ label: c.label, stroke: COLORS[i % COLORS.length], width: 1.5 }))],
        cursor: { sync: { key: sync.key } },
        legend: { live: true },
        hooks: { draw: [(p) => this.drawMarker(p)], ready: [(p) => p.over.addEventListener("click", () => this.pick(p))] },
      };
      const plot = new uPlot(opts, [this.x, ...members.map((c) => c.values)], this.area);
      plot.root.dataset.unit = unit;
      this.plots.push(plot);
    });
  }

  /** Move the state to the point under the cursor. */
  pick(p) {
    const i = p.cursor.idx;
    if (i != null && this.onPick) this.onPick(i);
  }

  /** Put the marker at x value `x` (the current state) on every chart. */
  mark(x) {
    this.marker = x;
    for (const p of this.plots) p.redraw(false, false);
  }

  drawMarker(p) {
    if (this.marker == null || !Number.isFinite(this.marker)) return;
    const ctx = p.ctx;
    const px = p.valToPos(this.marker, "x", true);
    ctx.save();
    ctx.strokeStyle = "#b3261e";
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    ctx.moveTo(px, p.bbox.top);
    ctx.lineTo(px, p.bbox.top + p.bbox.height);
    ctx.stroke();
    ctx.restore();
  }
}
