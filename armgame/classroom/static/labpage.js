// The browser lab's screen (PhET's Screen(createModel, createView)): LabScreen is the model and controller (the run,
// labengine.js's LabRun, played on the page's fixed-step clock; the cards, a reach's path for a moment after it, the
// end), LabView (labview.js) the view. It behaves as the lab window does (ui/lab_window.py): a card before the first
// trial says what to do and the keys, never what will happen; a card before each new block gives its instruction;
// the clock stops exactly at a trial's end while its path is shown (LabSession.steps_before_an_end, as TrialGate),
// so the keys the run records replay on the server to the same trials. play.js joins, reads keys and fingers, and
// hands the run in.
import { LabRun } from "./labengine.js";
import { figureMetric, learningCurve, outcomeWord, reachMeasure, resultWords } from "./labmeasure.js";
import { LabView } from "./labview.js";

/** How long a reach's path stays on screen after it (real seconds), as in the lab window. */
export const FEEDBACK_SECONDS = 1.2;
/** A frame longer than this (a stalled tab) is clamped, as the game's is. */
const MAX_FRAME = 0.25;

function plural(n, word) { return n + " " + word + (n === 1 ? "" : "s"); }

export class LabScreen {
  /** ``plan``: the class's plan (/api/labplan); ``player``: the name the replay is handed in under; ``touch``:
   * whether the buttons, not the keys, drive it (the cards say so). */
  constructor(plan, canvas, player, touch) {
    this.plan = plan;
    this.run = new LabRun(plan);
    this.view = new LabView(canvas, plan);
    this.player = player;
    this.touch = touch;
    this.metric = figureMetric(plan);
    this.phase = "card";  // card, reach, feedback, end
    this.feedback = null;
    this.held = new Set();
    this.clock = 0; this.taken = 0; this.alpha = 1;
    this.seen = 0;
    this.lastWords = ["", ""];
    this.curve = null;
    this.card = this._introCard();
    this._showCard();
    this._showHead();
  }

  get keys() { return this.run.muscleKeys; }

  /** The buttons came (a finger on the screen): the card on screen says the buttons, not the keys. */
  touched() {
    if (this.touch) return;
    this.touch = true;
    if (this.card !== null && this.run.outcomes.length === 0) this.card = this._introCard();
    this._showCard();
  }

  // ------------------------------------------------------------------ cards (LabWindow._intro_card, _block_card)
  _prompt() { return this.touch ? "Start" : "space starts"; }

  _introCard() {
    const keys = this.keys, blocks = this.plan.protocol.blocks, first = blocks[0];
    const how = this.touch
      ? `The ${keys[0]}/${keys[1]} buttons turn the shoulder, ${keys[2]}/${keys[3]} the elbow; home brings the hand home.`
      : `${keys[0]}/${keys[1]} turn the shoulder, ${keys[2]}/${keys[3]} the elbow; space brings the hand home.`;
    // What to do, never what will happen: a student told that something changes reaches differently.
    return { title: "The reaching lab", lines: [
      "Hold the cursor (the black dot) in the blue home circle.",
      "Wait for the target; then reach it and hold it there.",
      how,
      `${plural(this.plan.trials.length, "trial")} in ${plural(blocks.length, "block")}, a card before each.`,
      `Block 1 of ${blocks.length}: ${first.instruction || "reach each target and hold it."}`,
    ] };
  }

  _blockCard() {
    const trial = this.run.trial, last = this.run.outcomes.at(-1);
    if (trial === null || last === undefined || this.plan.trials[last.trial].block === trial.block) return null;
    const blocks = this.plan.protocol.blocks, block = blocks[trial.block];
    const lines = block.instruction ? [block.instruction] : [];
    return { title: `Block ${trial.block + 1} of ${blocks.length}: keep reaching`,
      lines: [...lines, plural(block.trials, "trial") + "."] };
  }

  _showCard() {
    if (this.card === null) this.view.card(null);
    else this.view.card(this.card.title, this.card.lines, this._prompt());
  }

  /** The card goes (space, Enter, or its button): the trials go on. */
  goOn() {
    if (this.phase !== "card") return;
    this.card = null;
    this._showCard();
    this.phase = "reach";
    this.clock = this.taken * this.run.dt;
  }

  // ------------------------------------------------------------------ keys
  /** A key ("d", "space"...) pressed: the run's input while the trials go; a card's "go on" while one is shown. */
  press(key) {
    if (this.phase === "card") { if (key === "space") this.goOn(); return; }
    if (this.phase !== "reach" || this.held.has(key)) return;
    if (key !== "space" && !this.keys.includes(key)) return;
    this.held.add(key);
    this.run.keyEvent(key, "down");
  }

  lift(key) {
    if (!this.held.delete(key)) return;
    if (this.phase === "reach") this.run.keyEvent(key, "up");
  }

  /** Every held key let go into the run (a trial's end, the tab hidden): LabWindow._stop_the_clock. */
  releaseAll() {
    for (const key of [...this.held]) this.lift(key);
  }

  // ------------------------------------------------------------------ the frame
  /** ``elapsed`` real seconds: the run's steps due, in fixed steps, stopping at a trial's end; cards and paths age. */
  frame(elapsed) {
    elapsed = Math.min(Math.max(elapsed, 0), MAX_FRAME);
    const run = this.run;
    if (this.phase === "reach") {
      const dt = run.dt;
      this.clock += elapsed;
      const due = Math.floor(this.clock / dt + 1e-9);
      const trials = run.outcomes.length;
      while (this.taken < due && !run.over && run.outcomes.length === trials) {
        const ran = run.advance(Math.min(due - this.taken, run.stepsBeforeAnEnd()));
        if (ran <= 0) break;
        this.taken += ran;
      }
      this.alpha = Math.min(Math.max(this.clock / dt - due, 0), 1);
      if (run.outcomes.length > trials) this._trialEnded();
      else if (run.over) this._end();
    } else if (this.phase === "feedback") {
      this.feedback.shownFor += elapsed;
      if (this.feedback.shownFor >= FEEDBACK_SECONDS) {
        this.feedback = null;
        if (run.over) { this._end(); return; }
        this.card = this._blockCard();
        this.phase = this.card === null ? "reach" : "card";
        this.clock = this.taken * run.dt;  // the real time a path or a card stood is not the run's
        this._showCard();
        this._showHead();
      }
    }
  }

  _trialEnded() {
    this.releaseAll();  // recorded as key-ups: the keys were let go as the clock stopped
    const run = this.run, outcome = run.outcomes.at(-1), trial = this.plan.trials[outcome.trial];
    const value = reachMeasure(outcome, trial, run.dt, this.metric);
    const verdict = outcomeWord(outcome, trial, this.plan.timeout_steps);
    // Knowledge of results only as the trial gives it: none on a trial without vision, not even a hit.
    const words = trial.feedback === "none" ? "reach done" : resultWords(value, this.metric, outcome.hit);
    this.feedback = { outcome, shownFor: 0 };
    this.lastWords = verdict === null ? [words, ""] : [verdict + ": " + words, outcome.hit ? "hit" : "miss"];
    this.phase = "feedback";
    this._showHead();
  }

  _showHead() {
    const run = this.run, total = this.plan.trials.length;
    const outcome = this.feedback?.outcome ?? null;
    const trial = outcome !== null ? this.plan.trials[outcome.trial] : run.trial;
    const number = outcome !== null ? outcome.trial + 1 : trial === null ? total : run.trialIndex + 1;
    const block = this.plan.protocol.blocks[(trial ?? this.plan.trials[total - 1]).block];
    let said = "", colour = "";
    if (outcome !== null) {
      [said, colour] = this.lastWords;
    } else if (run.outcomes.length > 0) {
      const last = run.outcomes.at(-1), lastTrial = this.plan.trials[last.trial];
      const word = outcomeWord(last, lastTrial, this.plan.timeout_steps);
      if (word === null) [said, colour] = ["last trial: reach done", ""];
      else if (last.hit) [said, colour] = [`last trial: hit, ${((last.endStep - last.goStep) * run.dt).toFixed(2)} s`, "hit"];
      else [said, colour] = ["last trial: " + word, "miss"];
    }
    this.view.head(`Trial ${number} of ${total} · ${block.name}`, block.instruction || "", said, colour);
  }

  _end() {
    if (this.phase === "end") return;
    this.phase = "end";
    this.releaseAll();
    const run = this.run;
    this.curve = learningCurve(this.plan, run.outcomes, run.dt);
    const unit = this.curve.unit;
    this.summary = `${this.plan.protocol.name}: ${plural(run.outcomes.length, "trial")}, ${plural(run.hits, "hit")}` +
      (run.finished ? "" : " (time is up)");
    this.means = "Block means: " + this.curve.blocks.map((b) => Number.isFinite(b.mean)
      ? `${b.name} ${b.mean >= 0 ? "+" : ""}${b.mean.toFixed(1)} ${unit}` : `${b.name} -`).join(",   ");
    this.view.card(null);
    this.view.end(this.summary, this.curve, this.means, "handing in…", "");
    this._showHead();
  }

  get over() { return this.phase === "end"; }

  /** The run's replay as the page hands it in. */
  replayJSON() { return this.run.replayJSON(this.player); }

  answer(line, kind) { this.view.answer(line, kind); }

  draw(w, h, sx, sy) {
    if (w < 1 || h < 1) return;
    this.view.draw(w, h, sx, sy, { run: this.run, feedback: this.feedback, phase: this.phase });
  }

  /** What the tests read: the phase, the trial, the keys held, the muscles, the home-key presses. */
  get debug() {
    return { lab: true, phase: this.phase, trial: this.run.trialIndex, trials: this.plan.trials.length,
      done: this.run.outcomes.length, held: [...this.held], activation: this.run.muscleActivation,
      resets: this.run.resets, steps: this.run.steps, go: this.run.phase === "reach" ? this.run.goStep : null };
  }
}
