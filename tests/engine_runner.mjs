// Plays games through armgame/classroom/static/engine.js for tests/test_browser_engine.py: one JSON request
// on stdin, one JSON answer on stdout. Doubles go out as their 64 bits in hex, so nothing (not even a zero's
// sign) is lost between the two languages.
import { readFileSync } from "node:fs";
import { Game, PythonRandom, sinCos, standardConfig, toJSON } from "../armgame/classroom/static/engine.js";
import { ARMGAME_VERSION } from "../armgame/classroom/static/constants.js";

const view = new DataView(new ArrayBuffer(8));
function bits(x) {
  view.setFloat64(0, x);
  return view.getBigUint64(0).toString(16).padStart(16, "0");
}

function play(job) {
  let game;
  try {
    game = new Game(job.config);
  } catch (error) {
    return { error: String(error.message) };
  }
  const applied = [];
  // TimelineInput.run_to's way: each event after advancing to its step; the steps in between in frames of
  // job.frame steps (a page's), which must not matter.
  const frame = job.frame ?? 1000000;
  const to = (step) => {
    while (game.steps < step && !game.over) {
      if (game.advance(Math.min(frame, step - game.steps)) === 0) break;
    }
  };
  const limit = Math.min(job.stop ?? game.totalSteps, game.totalSteps);
  for (const [step, key, action] of job.events) {
    if (step > limit) break;
    to(step);
    applied.push(game.keyEvent(key, action));
  }
  to(limit);
  const out = {
    score: game.score, hits: game.hits, resets: game.resets, steps: game.steps,
    hit_times: game.hitTimes.map(bits), state: game.state.map(bits),
    target: [game.target.x, game.target.y, game.target.radius].map(bits),
    hand: game.hand().map(bits), timeline: game.timeline, applied, tries: game.tries,
    arm_visible: game.armVisible, activation: game.muscleActivation.map(bits),
    interpolated: game.interpolatedAngles(0.25).map(bits), time_left: bits(game.timeLeft),
  };
  if (job.replay) out.replay = game.replayJSON(job.replay);
  return out;
}

const request = JSON.parse(readFileSync(0, "utf8"));
const answer = {
  armgame_version: ARMGAME_VERSION,
  games: (request.games ?? []).map(play),
  random: (request.random ?? []).map(([seed, count]) => {
    const rng = new PythonRandom(BigInt(seed));
    return Array.from({ length: count }, () => bits(rng.random()));
  }),
  sin_cos: (request.sin_cos ?? []).map((x) => sinCos(x).map(bits)),
  // a seed, or [seed, duration] (a rehearsal's clock)
  standard: (request.standard ?? []).map((s) => toJSON(Array.isArray(s) ? standardConfig(...s) : standardConfig(s))),
};
process.stdout.write(JSON.stringify(answer));
