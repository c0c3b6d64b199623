// Several marker boards in one image (issue 18): the engine's `boards`
// request finds every board of the target's layout, the target's own (its
// ids) and boards printed with other blocks of ids, e.g. Kalibr's two 6x6
// AprilGrids with tags 0-35 and 36-71. The target is one board: its points
// are the view's detection; the other boards are listed on the card with
// their counts and a button that makes one of them the target (every image
// is then detected again).
import { h, fill } from '../lib/dom.js';

/** Marker boards report the corners they see, any subset of the board's. */
export const MARKER_BOARDS = new Set(['charuco', 'aprilgrid', 'aruco_grid']);

/**
 * A card's point count. Whole-target kinds: "54 points". Marker boards:
 * "41 of 88 corners (partial view) · ids 0-5, 9-12, ..." (a partial view
 * is a valid detection: the solvers use any subset of the points).
 */
export function pointCount(points, board) {
  if (!board || !MARKER_BOARDS.has(board.kind)) return `${points.length} points`;
  const partial = points.length < board.total ? ' (partial view)' : '';
  return `${points.length} of ${board.total} corners${partial} · ids ${idRanges(points.map((p) => p.id))}`;
}

/** Sorted ids as ranges: [0,1,2,5,7,8] -> "0-2, 5, 7-8"; long lists end in "…". */
export function idRanges(ids, most = 6) {
  const runs = [];
  for (const id of [...ids].sort((a, b) => a - b)) {
    const last = runs[runs.length - 1];
    if (last && id === last[1] + 1) last[1] = id;
    else runs.push([id, id]);
  }
  const text = runs.slice(0, most).map(([a, b]) => (a === b ? `${a}` : `${a}-${b}`));
  return text.join(', ') + (runs.length > most ? ', …' : '');
}

/** What a card keeps of another board: its target JSON and its points. */
export const otherBoard = (d) => ({ target: d.target, first_id: d.target.first_id, points: d.points });

const firstIds = (boards) => boards.map((b) => b.first_id).join(', ');

/** The error of an image whose boards all carry other ids than the target's. */
export function notTheTarget(target, others) {
  const which = others.length === 1 ? `a board with first id ${others[0].first_id} is` : `boards with first ids ${firstIds(others)} are`;
  return `no board with the target's ids (first id ${target.first_id ?? 0}) in this image; ${which} in view: `
    + 'use it as the target with the button below, or set the first id in the target step';
}

/** The card's line about the other boards, e.g. "another board in view, first id 36: 144 of 144 corners · ids 0-143". */
export function otherBoardsText(others, count) {
  return others.map((b) => `another board in view, first id ${b.first_id}: ${count(b.points)}`).join(' · ');
}

/**
 * Fill `row` with one button per other board ("Use first id 36 as the
 * target"); `use(board)` makes it the target. Hidden when there is none.
 */
export function fillBoardButtons(row, others, name, use) {
  fill(row, ...others.map((b) => h('button', {
    type: 'button', class: 'small', 'aria-label': `use the board with first id ${b.first_id} in ${name} as the target`,
    onclick: () => use(b),
  }, `Use first id ${b.first_id} as the target`)));
  row.hidden = !others.length;
}

/** The other boards' points on a thumbnail (`X`, `Y` map image pixels to the canvas): small violet squares. */
export function drawOtherBoards(ctx, others, X, Y) {
  ctx.fillStyle = '#9467bd';
  for (const b of others) for (const p of b.points) ctx.fillRect(X(p.x_px) - 2, Y(p.y_px) - 2, 4, 4);
}
