// Hand-eye capture: a robot pose typed or pasted (one line, any format the
// robot step reads) goes with the next captured frame. The lines of the
// captured frames, in the images' order, become the session's pose text,
// read by the robot step as if it were a file (paired by order: pose i with
// image i). A pose file loaded in step 4 instead replaces them: it pairs by
// order (or by its name column) as always.
import { $ } from '../lib/dom.js';

/** The robot step's file name for the typed poses (a loaded file has its own name). */
export const TYPED_POSES = 'poses typed at capture';

export class CapturePoses {
  /** `robot()` gives the RobotView (its reading options and parse) once it exists. */
  constructor(store, engine, robot) {
    this.store = store;
    this.engine = engine;
    this.robot = robot;
  }

  /** The line typed for the next capture ('' when none). */
  get line() { return $('capture-pose').value.trim(); }

  /**
   * Read the typed line with the robot step's options: the reading
   * (format and units) or an Error with the parser's message.
   */
  async check(line) {
    const view = this.robot();
    const options = view ? view.options() : { direction: 'base_from_gripper' };
    const reading = await this.engine.call('poses', { text: line, options: JSON.stringify(options) });
    const parsed = reading.parsed || reading.candidates[0];
    if (!parsed || parsed.poses.length !== 1) throw new Error(`expected one pose on the line, read ${parsed ? parsed.poses.length : 0}`);
    return parsed;
  }

  note(text) { $('capture-pose-note').textContent = text; }

  /** After a capture named `name` with `line`: clear the field, say what was read, update the robot step. */
  async captured(name, line, reading) {
    $('capture-pose').value = '';
    this.note(`${name} is paired with the pose read as ${reading.format} (lengths in ${reading.length_unit}, angles in ${reading.angle_unit}). Type the next pose before the next capture.`);
    await this.sync();
  }

  /**
   * The typed lines of the session's images, in order, as the robot step's
   * pose text (unless a pose file was loaded there: it is kept).
   */
  async sync() {
    const st = this.store.session.robot;
    if (st.fileName && st.fileName !== TYPED_POSES) return;
    const lines = this.store.session.images.filter((i) => i.robotPose).map((i) => i.robotPose);
    const text = `${lines.join('\n')}\n`;
    if (!lines.length || (st.fileName === TYPED_POSES && st.text === text)) return;
    st.fileName = TYPED_POSES;
    st.text = text;
    st.files = null;
    const view = this.robot();
    if (view) { view.render(); await view.parse(); } else this.store.changed('robot');
  }
}
