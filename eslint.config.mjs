// ESLint's flat config for the class's browser pages (armgame/classroom/static/*.js): ESLint's recommended rules on
// plain ES modules in a browser, and the few the house holds to; and for the tests' Node modules (tests/*.mjs).
// .ci/run installs ESLint 9 and `globals` into a temporary folder (npm install --no-save --prefix DIR eslint@9
// globals@16) and runs DIR/node_modules/.bin/eslint; this file then finds both beside that ESLint, so the
// repository needs no node_modules and the README's test command no npm. It lies outside the package: the wheel
// does not ship it.
import { createRequire } from "node:module";

// Beside the ESLint that runs this file (process.argv[1] is its bin script); else wherever Node finds them.
const beside = createRequire(process.argv[1]);
const load = async (name) => { try { return beside(name); } catch { return (await import(name)).default; } };
const js = await load("@eslint/js");
const globals = await load("globals");

export default [
  js.configs.recommended,
  {
    files: ["armgame/classroom/static/*.js"],
    languageOptions: { ecmaVersion: 2022, sourceType: "module", globals: globals.browser },
    rules: {
      // Every name is read: a name nothing reads is dead code (engine.js lost two so).
      "no-unused-vars": ["error", { args: "after-used", caughtErrors: "none" }],
      // A name inside a function that hides one outside means two things in one module (play.js's `taken`).
      "no-shadow": ["error", { builtinGlobals: false, hoist: "functions" }],
      // Text is set with textContent, never as HTML from data; no code is made from strings.
      "no-restricted-properties": ["error",
        { property: "innerHTML", message: "set text with textContent" },
        { property: "outerHTML", message: "set text with textContent" },
        { property: "insertAdjacentHTML", message: "set text with textContent" }],
      "no-eval": "error",
      "no-implied-eval": "error",
      "no-new-func": "error",
      "eqeqeq": ["error", "always"],
      "no-var": "error",
      "prefer-const": "error",
    },
  },
  // The tests that run the pages' modules in Node (node --test) and the engine's runner.
  { files: ["tests/*.mjs"], languageOptions: { ecmaVersion: 2022, sourceType: "module", globals: globals.node } },
];
