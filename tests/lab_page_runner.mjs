// Measures lab runs as the browser's lab screen tells a student (armgame/classroom/static/labmeasure.js), for
// tests/test_lab_page.py: one JSON request on stdin ({plan, events, stop}), the run played through labengine.js
// on its key timeline, and one JSON answer on stdout: each reach's two measures, what the student was told of it
// (the outcome word and the result's words), and the learning curve the end screen draws.
import { readFileSync } from "node:fs";
import { LabRun } from "../armgame/classroom/static/labengine.js";
import { DIRECTION, PERPENDICULAR, figureMetric, learningCurve, outcomeWord, reachMeasure, resultWords }
  from "../armgame/classroom/static/labmeasure.js";

const finite = (x) => (Number.isFinite(x) ? x : null);
const request = JSON.parse(readFileSync(0, "utf8"));
const answers = request.runs.map(({ plan, events, stop }) => {
  const run = new LabRun(plan);
  const to = (step) => {
    while (run.steps < step && !run.over) if (run.advance(Math.min(run.stepsBeforeAnEnd(), step - run.steps)) === 0) break;
  };
  for (const [step, key, action] of events) {
    if (step > stop) break;
    to(step);
    run.keyEvent(key, action);
  }
  to(Math.min(stop, run.totalSteps));
  const metric = figureMetric(plan);
  const reaches = run.outcomes.map((o) => {
    const trial = plan.trials[o.trial];
    const value = reachMeasure(o, trial, run.dt, metric);
    return { perpendicular: finite(reachMeasure(o, trial, run.dt, PERPENDICULAR)),
      direction: finite(reachMeasure(o, trial, run.dt, DIRECTION)), word: outcomeWord(o, trial, plan.timeout_steps),
      words: resultWords(value, metric, o.hit) };
  });
  const curve = learningCurve(plan, run.outcomes, run.dt);
  return { metric, reaches, curve: { ...curve, points: curve.points.map((p) => ({ ...p, value: finite(p.value) })),
    blocks: curve.blocks.map((b) => ({ ...b, mean: finite(b.mean) })) } };
});
process.stdout.write(JSON.stringify(answers));
