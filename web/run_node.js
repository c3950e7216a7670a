// The pendulum's wasm FMU in Node: the module jco transpiled from the component, run on a torque
// signal by the same host as the docs page (fmu_host.js).
//
//   node web/run_node.js PAGE_DIR [--torque N.m | --torque-file torque.csv] [--stop-time s]
//       [--step-size s] [--output-file result.csv] [--model-exchange SUBSTEPS]
//
// PAGE_DIR holds what `python -m fmu_build.wasm_page` made: fmu.js (jco's output), its core wasm
// files and fmu.json. Prints theta at the stop time as JSON; --output-file writes the result CSV
// `pendulum-fmu judge` reads. --model-exchange runs the Model Exchange interface instead, under the
// host's classic Runge-Kutta, SUBSTEPS steps per communication step.
import { readFileSync, writeFileSync } from "node:fs";
import { join, resolve } from "node:path";
import { pathToFileURL } from "node:url";
import { parseArgs } from "node:util";
import { fmiCallbacks, parseTorqueCsv, resultCsv, runCoSimulation, runModelExchange, schedule } from "./fmu_host.js";

const { values, positionals } = parseArgs({
  allowPositionals: true,
  options: {
    torque: { type: "string", default: "20" },
    "torque-file": { type: "string" },
    "stop-time": { type: "string", default: "3" },
    "step-size": { type: "string", default: "0.001" },
    "output-file": { type: "string" },
    "model-exchange": { type: "string" },
  },
});

function fail(message) {
  console.error(`run_node.js: ${message}`);
  process.exit(2);
}

async function main() {
  if (positionals.length !== 1) fail("give the folder `python -m fmu_build.wasm_page` made");
  const folder = resolve(positionals[0]);
  const fmu = JSON.parse(readFileSync(join(folder, "fmu.json"), "utf-8"));
  const { instantiate } = await import(pathToFileURL(join(folder, "fmu.js")).href);
  const messages = [];
  const exports = await instantiate(
    (name) => WebAssembly.compile(readFileSync(join(folder, name))),
    fmiCallbacks((message) => messages.push(message)),
  );
  const signal = values["torque-file"]
    ? { kind: "csv", rows: parseTorqueCsv(readFileSync(values["torque-file"], "utf-8")) }
    : { kind: "constant", value: Number(values.torque) };
  const plan = schedule(signal, 0, Number(values["stop-time"]), Number(values["step-size"]));
  const started = process.hrtime.bigint();
  const substeps = Number(values["model-exchange"]);
  if (values["model-exchange"] !== undefined && !(Number.isInteger(substeps) && substeps >= 1)) {
    fail(`--model-exchange ${values["model-exchange"]}: give a whole number of Runge-Kutta steps per step, at least 1`);
  }
  const columns = values["model-exchange"] === undefined
    ? runCoSimulation(exports, fmu, plan, messages)
    : runModelExchange(exports, fmu, plan, substeps, messages);
  const seconds = Number(process.hrtime.bigint() - started) / 1e9;
  if (values["output-file"]) writeFileSync(values["output-file"], resultCsv(columns));
  const last = columns.time.length - 1;
  console.log(JSON.stringify({ time: columns.time[last], theta: columns.theta[last], steps: last, seconds, messages }));
}

main().catch((error) => fail(error.message));
