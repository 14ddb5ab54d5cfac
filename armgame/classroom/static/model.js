// The browser game's model (/play): the class's game (engine.js's Game, bit for bit the Python's) on the page's
// clock: the countdown, real time consumed in fixed steps, and the hits the view flashes. No page, no drawing:
// play.js feeds it each frame's elapsed seconds and the keys, view.js draws what it holds.
import { Game, standardConfig } from "./engine.js";

// A frame longer than this (a stalled tab) is clamped: the game slows for a moment rather than jumping
// (RealTimeDriver's max_frame_time in game/session.py).
export const MAX_FRAME = 0.25;
// The countdown before a game, in seconds (any key or tap ends it sooner).
export const COUNTDOWN = 3;
// A hit's flash and "+1" last this long; the next target fades in over FADE_IN (ui/render.py's, seconds of game
// time): a hit is remembered for the longer of them.
export const FLASH_TIME = 0.35, PLUS_ONE_TIME = 0.9, FADE_IN = 0.3;

export class PlayedGame {
  // ``member``: the name playing, {seed, duration}: the class's seed and clock (a class that does not say: 60 s).
  constructor(member) {
    this.config = standardConfig(member.seed, member.duration ?? 60);
    this.game = new Game(this.config);
    this.names = this.config.muscles.map((m) => m.name);
    this.keys = this.game.muscleKeys;
    this.countdownLeft = COUNTDOWN;
    this.clock = 0;  // real seconds consumed, a running total: a 30 Hz and a 144 Hz display reach a step together
    this.taken = 0;  // the steps the clock has reached
    this.alpha = 1;  // how far the drawing is between the last step and the next
    this.hits = [];  // [x, y, game time] of the recent hits, the oldest first
    this.seenHits = 0;
    this.lastTarget = this.game.target;
  }

  // The countdown's real time: true once it has run out.
  countDown(elapsed) {
    this.countdownLeft -= Math.max(elapsed, 0);
    return this.countdownLeft <= 0;
  }

  // Real time consumed in fixed steps (RealTimeDriver in game/session.py): true once the game is over.
  advance(elapsed) {
    const game = this.game, dt = game.dt;
    this.clock += Math.min(Math.max(elapsed, 0), MAX_FRAME);
    const due = Math.floor(this.clock / dt + 1e-9);
    if (due > this.taken) {
      game.advance(due - this.taken);
      this.taken = due;
    }
    this.alpha = Math.min(Math.max(this.clock / dt - due, 0), 1);
    this.noteHits();
    if (game.over) this.alpha = 1;
    return game.over;
  }

  // The game time now (s).
  get now() { return this.game.steps * this.game.dt; }

  noteHits() {
    const game = this.game, now = this.now;
    if (game.hits > this.seenHits && this.lastTarget !== null) this.hits.push([this.lastTarget.x, this.lastTarget.y, now]);
    this.seenHits = game.hits;
    this.lastTarget = game.target;
    this.hits = this.hits.filter((h) => now - h[2] < Math.max(PLUS_ONE_TIME, FADE_IN));
  }
}
