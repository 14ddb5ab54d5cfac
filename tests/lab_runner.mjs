// Plays lab runs through armgame/classroom/static/labengine.js for tests/test_browser_lab.py: one JSON request on
// stdin ({plans, runs: [{plan, events, stop, frame, replay}]}, a run naming its plan by index), one JSON answer on
// stdout. Doubles go out as their 64 bits in hex, so nothing (not even a zero's sign) is lost between the two.
import { readFileSync } from "node:fs";
import { LabRun } from "../armgame/classroom/static/labengine.js";

const view = new DataView(new ArrayBuffer(8));
function bits(x) {
  view.setFloat64(0, x);
  return view.getBigUint64(0).toString(16).padStart(16, "0");
}

function play(job, plans) {
  let run;
  try {
    run = new LabRun(plans[job.plan]);
  } catch (error) {
    return { error: String(error.message) };
  }
  const applied = [];
  // TimelineInput.run_to's way: each event after advancing to its step. Between events the page advances in
  // frames: job.frame steps, or (frame 0) as the lab window does, never past a trial's soonest end.
  const to = (step) => {
    while (run.steps < step && !run.over) {
      const frame = job.frame === 0 ? run.stepsBeforeAnEnd() : job.frame;
      if (run.advance(Math.min(frame, step - run.steps)) === 0) break;
    }
  };
  const limit = Math.min(job.stop ?? run.totalSteps, run.totalSteps);
  for (const [step, key, action] of job.events) {
    if (step > limit) break;
    to(step);
    applied.push(run.keyEvent(key, action));
  }
  to(limit);
  const out = {
    trials: run.trialRecords(), steps: run.steps, score: run.score, hits: run.hits, resets: run.resets,
    finished: run.finished, phase: run.phase, trial_index: run.trialIndex, state: run.state.map(bits),
    cursor: run.cursor.map(bits), activation: run.muscleActivation.map(bits), target: [run.target.x,
      run.target.y, run.target.radius].map(bits), home: run.home.map(bits), home_at: run.outcomes.map((o) => o.homeAt),
    paths_sha256: run.pathsDigest(), timeline: run.timeline, applied,
  };
  if (job.replay) out.replay = run.replayJSON(job.replay);
  return out;
}

const request = JSON.parse(readFileSync(0, "utf8"));
const started = performance.now();
const runs = request.runs.map((job) => play(job, request.plans));
process.stdout.write(JSON.stringify({ runs, ms: performance.now() - started }));
