// Node tier: the LiveCapture class of the npm package (docs/live-capture.md)
// fed the frames of `robocal render --video` (smoke.mjs renders live.y4m and
// its truth live.json in WORK_DIR; run as `node live.mjs WORK_DIR`). The
// video's luma is video-range (16-235) and goes back to 0-255 as the page
// does (www/lib/frames.js). Asserted against the video's truth: frames are
// kept only in holds (never while the board moves), at most one per hold;
// an excluded capture leaves the coverage and calibration and comes back;
// the coverage counts match the kept frames' true points; the tilt signs
// match what a viewer sees (top / right edge farther); a hold seen again
// adds nothing; the running calibration finds the video's camera within 4
// of its standard deviations; good_enough follows the documented rule.
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';

const work = process.argv[2];
if (!work) throw new Error('usage: node live.mjs WORK_DIR (with robocal installed and live.y4m rendered)');
const robocal = createRequire(join(work, 'package.json'))('robocal');
const truth = JSON.parse(readFileSync(join(work, 'live.json'), 'utf8'));
const [W, H] = truth.size_px;

/** The grey frames of a 4:2:0 Y4M file (luma stretched from video range to 0-255). */
function y4mFrames(bytes) {
  const line = (at) => { const end = bytes.indexOf(0x0a, at); return [bytes.subarray(at, end).toString('latin1'), end + 1]; };
  let [header, at] = line(0);
  const w = Number(/ W(\d+)/.exec(header)[1]);
  const h = Number(/ H(\d+)/.exec(header)[1]);
  const frames = [];
  while (at < bytes.length) {
    [header, at] = line(at);
    assert.match(header, /^FRAME/);
    const grey = new Uint8Array(w * h);
    for (let i = 0; i < w * h; i++) grey[i] = Math.min(255, Math.max(0, Math.round(((bytes[at + i] - 16) * 255) / 219)));
    frames.push(grey);
    at += w * h + 2 * (w / 2) * (h / 2);
  }
  return { w, h, frames };
}

const video = y4mFrames(readFileSync(join(work, 'live.y4m')));
assert.deepEqual([video.w, video.h, video.frames.length], [W, H, truth.frames.length]);
const spec = robocal.target_spec(JSON.stringify(truth.target));
const live = new robocal.LiveCapture(spec, W, H);

// Errors say what to fix.
assert.throws(() => new robocal.LiveCapture(spec, 8, 8), { message: /^frame size: expected a frame of at least 16x16 and at most 100 MP, got 8x8/ });
assert.throws(() => live.push_grey(new Uint8Array(10), W, H, 0), { message: /10/ });
assert.throws(() => live.calibrate(), { message: /the running calibration needs at least 4 captures, got 0: keep capturing/ });

const start = JSON.parse(live.state());
assert.deepEqual([start.kept, start.good_enough, start.suggestion.rule], [0, false, 'coverage']);
const firstSuggestion = JSON.stringify(start.suggestion.outline_px);

const reports = truth.frames.map((f, i) => ({ truth: f, r: JSON.parse(live.push_grey(video.frames[i], W, H, f.time_ms)) }));
const kept = reports.filter(({ r }) => r.keep);
const reasons = (want) => reports.filter(({ r }) => r.reason === want);
// Never while moving: every kept frame lies in a hold, at most one per hold,
// and not on its first two frames (stillness needs 250 ms of history).
for (const { truth: f } of kept) assert.notEqual(f.hold, null, `frame ${f.index} kept outside a hold`);
const holdsKept = kept.map(({ truth: f }) => f.hold);
assert.equal(new Set(holdsKept).size, holdsKept.length, `one capture per hold: ${holdsKept}`);
for (const { truth: f } of kept) assert.ok(f.index - truth.holds[f.hold].first_frame >= 2, `frame ${f.index} kept before the board settled`);
assert.ok(kept.length >= 8, `captures from the 12 holds: ${holdsKept}`);
// Each hold is kept on its first frame with 250 ms of still history (its
// third at 5 fps), or refused from then on only for adding nothing new.
truth.holds.forEach((h, i) => {
  const still = reports.slice(h.first_frame + 2, h.last_frame + 1).map(({ r }) => r.reason);
  const want = holdsKept.includes(i) ? ['kept', ...still.slice(1).map(() => 'nothing_new')] : still.map(() => 'nothing_new');
  assert.deepEqual(still, want, `hold ${i}`);
});
// The board moves between holds: those frames are refused as moving (or settling, as it enters).
assert.ok(reasons('moving').length > 0 && reasons('moving').every(({ truth: f }) => f.hold === null || f.index - truth.holds[f.hold].first_frame < 2), 'moving frames are the moves');
assert.ok(reasons('not_found').every(({ truth: f }) => f.hold === null), 'the board is found in every hold');
const last = reports[reports.length - 1].r;
assert.equal(last.kept, kept.length);

// Coverage against the truth: each kept frame counted once in tilt and distance, the cells those of its true points.
assert.equal(last.coverage.kept, kept.length);
assert.equal(last.coverage.tilt.flat().reduce((a, b) => a + b, 0), kept.length);
assert.equal(last.coverage.distance.reduce((a, b) => a + b, 0), kept.length);
const [cols, rows] = last.coverage.grid;
const trueCells = new Array(cols * rows).fill(0);
for (const { truth: f } of kept) for (const p of f.points) trueCells[Math.floor((p.y_px / H) * rows) * cols + Math.floor((p.x_px / W) * cols)]++;
// Detected points are within a pixel of the truth: only a point on a cell border may change cell.
const off = last.coverage.cells.reduce((s, n, i) => s + Math.abs(n - trueCells[i]), 0);
assert.ok(off <= 0.02 * kept.length * 54, `points per cell differ from the truth's by ${off}`);
assert.deepEqual(last.coverage.cells.map((n) => n > 0), trueCells.map((n) => n > 0));

// Tilt signs as a viewer sees them: positive about x when the board's top
// (in the image) is farther than its bottom; about y when its right is.
const objects = new Map(JSON.parse(robocal.target_points(spec)).map((p) => [p.id, p]));
for (const { truth: f, r } of kept) {
  const m = f.camera_from_target.matrix_row_major;
  const depth = (id) => { const o = objects.get(id); return m[2][0] * o.x_m + m[2][1] * o.y_m + m[2][3]; };
  const byY = [...f.points].sort((a, b) => a.y_px - b.y_px);
  const byX = [...f.points].sort((a, b) => a.x_px - b.x_px);
  const mean = (ps) => ps.reduce((s, p) => s + depth(p.id), 0) / ps.length;
  const k = 9;
  const topAway = mean(byY.slice(0, k)) - mean(byY.slice(-k));
  const rightAway = mean(byX.slice(-k)) - mean(byX.slice(0, k));
  const { tilt_x_deg: tx, tilt_y_deg: ty } = r.signature;
  if (Math.abs(tx) > 5) assert.equal(Math.sign(tx), Math.sign(topAway), `frame ${f.index}: tilt about x ${tx} deg, top - bottom depth ${topAway} m`);
  if (Math.abs(ty) > 5) assert.equal(Math.sign(ty), Math.sign(rightAway), `frame ${f.index}: tilt about y ${ty} deg, right - left depth ${rightAway} m`);
}
assert.ok(kept.some(({ r }) => Math.abs(r.signature.tilt_x_deg) > 15) && kept.some(({ r }) => Math.abs(r.signature.tilt_y_deg) > 15), 'the video tilts about both axes');

// The suggestion moved on as coverage grew.
assert.equal(last.suggestion.rule, 'coverage');
assert.notEqual(JSON.stringify(last.suggestion.outline_px), firstSuggestion);

// A kept hold seen again (its frames replayed later) adds nothing.
const again = truth.holds[kept[0].truth.hold];
let t = truth.frames[truth.frames.length - 1].time_ms;
let replay;
for (let i = again.first_frame; i <= again.last_frame; i++) replay = JSON.parse(live.push_grey(video.frames[i], W, H, (t += 200)));
assert.deepEqual([replay.still, replay.keep, replay.reason], [true, false, 'nothing_new']);
assert.throws(() => live.push_grey(video.frames[0], W, H, t), { message: `frame time: expected a time in ms after the previous frame's ${t}, got ${t}` });

// The running calibration: the video's camera within 4 sigma (and 0.5 px / 0.005 for quantisation).
const cal = JSON.parse(live.calibrate());
const c = truth.camera;
const k = cal.calibration.camera_matrix;
const std = cal.calibration.std;
for (const [name, got, want] of [['fx', k[0][0], c.fx], ['fy', k[1][1], c.fy], ['cx', k[0][2], c.cx], ['cy', k[1][2], c.cy], ['k1', cal.calibration.distortion.k1, c.distortion.k1]]) {
  const tol = Math.max(4 * std[name], name === 'k1' ? 0.005 : 0.5);
  assert.ok(Math.abs(got - want) <= tol, `${name} ${got} vs true ${want} (std ${std[name]})`);
}
assert.equal(cal.kept, kept.length);
// Good enough: at least 8 captures and the worst projection uncertainty below 0.2 px; then no suggestion.
assert.equal(cal.good_enough, kept.length >= 8 && cal.max_std_px < 0.2);
assert.equal(live.good_enough(), cal.good_enough);
assert.equal(cal.suggestion === null, cal.good_enough);
if (cal.suggestion) assert.equal(cal.suggestion.rule, 'uncertainty');
// Manual capture keeps the last frame with the board even when the rule would not (hold 6 adds nothing new).
const notKept = truth.holds.findIndex((_, i) => !holdsKept.includes(i));
const manualFrame = JSON.parse(live.push_grey(video.frames[truth.holds[notKept].last_frame], W, H, (t += 200)));
assert.equal(manualFrame.keep, false);
const manual = JSON.parse(live.capture());
assert.deepEqual([manual.index, manual.kept, manual.coverage.kept], [kept.length, kept.length + 1, kept.length + 1]);
live.remove(kept.length);

// Excluding a capture (its card unticked) sets it aside, its index kept; including it brings it back.
const before = JSON.parse(live.state());
const out = JSON.parse(live.set_included(1, false));
assert.deepEqual([out.kept, out.used, out.coverage.kept], [before.kept, before.kept - 1, before.kept - 1]);
const without = JSON.parse(live.calibrate());
assert.deepEqual([without.used, without.calibration.views.length], [before.kept - 1, before.kept - 1]);
assert.ok(!without.calibration.views.some((v) => v.name === 'capture_001'), 'capture 1 is left out');
const back = JSON.parse(live.set_included(1, true));
assert.deepEqual([back.kept, back.used, back.coverage.kept, back.coverage.cells], [before.kept, before.kept, before.kept, before.coverage.cells]);
assert.throws(() => live.set_included(before.kept, false), { message: `capture: expected a capture index below ${before.kept}, got ${before.kept}` });

// Hand-eye guide: robot rotations about one axis are not diverse; one about another axis makes them so.
const q = (axis, deg) => { const h = (deg * Math.PI) / 360; return [...axis.map((a) => a * Math.sin(h)), Math.cos(h)]; };
const robot = (i, axis, deg) => JSON.parse(live.set_robot_pose(i, JSON.stringify({ translation_m: [0.4, 0.1 * i, 0.3], quaternion_xyzw: q(axis, deg) })));
robot(0, [0, 0, 1], 0);
robot(1, [0, 0, 1], 20);
const aboutZ = robot(2, [0, 0, 1], 45).handeye;
assert.equal(aboutZ.poses, 3);
assert.ok(aboutZ.axis_spread_deg < 1 && Math.abs(Math.abs(aboutZ.dominant_axis[2]) - 1) < 1e-6 && !aboutZ.enough, JSON.stringify(aboutZ));
const mixed = robot(3, [1, 0, 0], 30).handeye;
assert.ok(mixed.axis_spread_deg >= 30 && mixed.enough, JSON.stringify(mixed));
assert.throws(() => live.set_robot_pose(0, '{"translation_m": [0, 0]}'), { message: /^robot pose JSON: / });

// Removing captures down to 4 keeps the calibration possible but not good enough (fewer than 8 views).
for (let i = kept.length - 1; i >= 4; i--) live.remove(i);
const four = JSON.parse(live.calibrate());
assert.deepEqual([four.kept, four.good_enough, four.suggestion.rule], [4, false, 'uncertainty']);
assert.equal(JSON.parse(live.kept_detections()).length, 4);
console.log(`LiveCapture: ${kept.length} captures from holds ${holdsKept.join(' ')}; calibration fx ${k[0][0].toFixed(2)} ± ${std.fx.toFixed(2)} (true ${c.fx}), worst projection uncertainty ${cal.max_std_px.toFixed(3)} px, good enough: ${cal.good_enough}`);
live.free();
