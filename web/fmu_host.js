// The host of the pendulum's wasm FMU (FMI-LS-WASM, FMI 3.0 Co-Simulation) for JavaScript: the
// same module runs in Node (web/run_node.js) and in the docs page (web/page.js).
//
// `jco transpile --instantiation async` turns the component into an ES module whose
// instantiate(getCoreModule, imports) takes the component's imports from the host: here the FMI
// callbacks and nothing else, the whole of what the FMU can reach.
//
// The schedule follows pendulum_fmu/signals (docs/signals.md), held mode: communication points
// start + k*h, each step holding the torque just after its start, a CSV's jumps between grid points
// becoming points of their own, times within the event tolerance of a grid point being that point.

const EVENT_TOLERANCE_STEPS = 1e-9; // pendulum_fmu/signals/_time_grid.py
const EVENT_TOLERANCE_ULPS = 64;
// The columns of a result, in pendulum_fmu.fmu._results' order: what `judge` reads.
export const RESULT_COLUMNS = ["time", "torque", "theta", "omega", "alpha"];
const RECORDED = ["torque", "theta", "omega", "alpha"];
// The most steps a page or script runs, as pendulum_fmu's default --max-steps.
export const MAX_STEPS = 10_000_000;

function ulp(x) {
  const magnitude = Math.abs(x);
  if (magnitude === 0) return Number.MIN_VALUE;
  const exponent = Math.floor(Math.log2(magnitude));
  return Math.max(2 ** (exponent - 52), Number.MIN_VALUE);
}

function eventTolerance(time, stepSize) {
  return Math.max(EVENT_TOLERANCE_STEPS * stepSize, EVENT_TOLERANCE_ULPS * ulp(time));
}

/** The communication points start, start + h, ... up to stop (pendulum_fmu's communication_points). */
export function communicationPoints(startTime, stopTime, stepSize) {
  for (const [name, value] of [["start time", startTime], ["stop time", stopTime], ["step size", stepSize]]) {
    if (!Number.isFinite(value)) throw new Error(`${name} ${value} must be a finite number of seconds`);
  }
  if (!(stepSize > 0)) throw new Error(`step size ${stepSize} must be positive`);
  if (!(stopTime > startTime)) throw new Error(`stop time ${stopTime} must be after start time ${startTime}`);
  const span = stopTime - startTime;
  let steps = Math.floor(span / stepSize);
  if (span - steps * stepSize > eventTolerance(stopTime, stepSize)) steps += 1;
  steps = Math.max(steps, 1);
  if (steps > MAX_STEPS) throw new Error(`${steps} steps is over the limit of ${MAX_STEPS}: use a coarser step`);
  const grid = Array.from({ length: steps + 1 }, (_, k) => startTime + stepSize * k);
  if (Math.abs(grid[steps] - stopTime) > eventTolerance(stopTime, stepSize)) grid[steps] = stopTime;
  return grid;
}

// The largest torque CSV read (characters): far past any signal a page runs (MAX_STEPS rows).
export const MAX_CSV_CHARS = 256 * 2 ** 20;

/** A torque CSV (time,torque; fmpy's convention) as rows [time, value], or an Error naming the line. */
export function parseTorqueCsv(text) {
  if (text.length > MAX_CSV_CHARS) throw new Error(`over ${MAX_CSV_CHARS / 2 ** 20} MiB: not a torque CSV this page reads`);
  const lines = text.replace(/^\uFEFF/, "").split(/\r?\n/);
  const header = lines[0].split(",").map((cell) => cell.trim());
  const timeColumn = header.indexOf("time");
  const torqueColumn = header.indexOf("torque");
  if (timeColumn < 0 || torqueColumn < 0) throw new Error("line 1: expected a header time,torque");
  const rows = [];
  lines.slice(1).forEach((line, index) => {
    if (!line.trim()) return;
    const cells = line.split(",");
    const time = Number(cells[timeColumn]);
    const value = Number(cells[torqueColumn]);
    if (!Number.isFinite(time) || !Number.isFinite(value)) {
      throw new Error(`line ${index + 2}: '${line.slice(0, 40)}' is not a time and a torque`);
    }
    if (rows.length && time < rows[rows.length - 1][0]) throw new Error(`line ${index + 2}: the time goes back`);
    if (rows.length > 1 && time === rows[rows.length - 1][0] && time === rows[rows.length - 2][0]) {
      throw new Error(`line ${index + 2}: time ${time} appears three times; a jump is two rows with the same time`);
    }
    rows.push([time, value]);
  });
  if (!rows.length) throw new Error("no rows after the header");
  return rows;
}

/** The CSV's value just after t (held before its first row and after its last, linear between). */
function valueAfter(rows, t) {
  let i = -1;
  while (i + 1 < rows.length && rows[i + 1][0] <= t) i += 1;
  if (i < 0) return rows[0][1];
  if (i === rows.length - 1) return rows[i][1];
  const [t0, v0] = rows[i];
  const [t1, v1] = rows[i + 1];
  return v0 + ((v1 - v0) * (t - t0)) / (t1 - t0);
}

/**
 * The schedule of a signal: {time: points, torque: one value per step}. signal is
 * {kind: "constant", value} | {kind: "step", before, after, at} | {kind: "csv", rows}.
 */
export function schedule(signal, startTime, stopTime, stepSize) {
  let grid = communicationPoints(startTime, stopTime, stepSize);
  if (signal.kind === "constant") return { time: grid, torque: grid.slice(0, -1).map(() => signal.value) };
  const rows = signal.kind === "step" ? [[signal.at, signal.before], [signal.at, signal.after]] : signal.rows;
  // Row times within the event tolerance of a grid point are that point.
  const snapped = rows.map(([t, v]) => {
    const near = grid.reduce((best, point) => (Math.abs(point - t) < Math.abs(best - t) ? point : best));
    return [Math.abs(near - t) <= eventTolerance(t, stepSize) ? near : t, v];
  });
  const jumps = snapped.filter(([t], i) => i > 0 && t === snapped[i - 1][0]).map(([t]) => t);
  const inside = jumps.filter((t) => t > grid[0] && t < grid[grid.length - 1] && !grid.includes(t));
  grid = [...new Set([...grid, ...inside])].sort((a, b) => a - b);
  return { time: grid, torque: grid.slice(0, -1).map((t) => valueAfter(snapped, t)) };
}

/** The component's imports: the FMI callbacks, the only things the FMU can call. */
export function fmiCallbacks(log) {
  return {
    "fmi:fmi3/callbacks": {
      logMessage: (instanceName, status, category, message) => log(`${instanceName} [${status}] ${category}: ${message}`),
      clockUpdate: () => {},
      lockPreemption: () => {},
      unlockPreemption: () => {},
    },
    "fmi:fmi3/intermediate-update-callbacks": {
      // Early return is never allowed by this host: the FMU is not asked to stop early.
      intermediateUpdate: () => [false, 0],
    },
  };
}

/** What the FMU logged, as the end of an error's message. */
const logged = (messages) => (messages.length ? `: ${messages.join("; ")}` : "");

function checked(status, what, messages) {
  if (status !== "ok" && status !== "warning") throw new Error(`${what} returned ${status}${logged(messages)}`);
}

function call(what, messages, thunk) {
  try {
    return thunk();
  } catch (error) {
    throw new Error(`${what} returned ${error?.payload ?? error?.message ?? error}${logged(messages)}`);
  }
}

/**
 * The instance (either kind) initialized over the plan's time, with the result's empty columns
 * and the value references a run sets and reads.
 */
function initialized(instance, fmu, time, messages) {
  if (!instance) throw new Error(`the FMU refused to instantiate${logged(messages)}`);
  checked(instance.enterInitializationMode(undefined, time[0], time[time.length - 1]), "enterInitializationMode", messages);
  checked(instance.exitInitializationMode(), "exitInitializationMode", messages);
  return {
    torqueVr: new Uint32Array([fmu.valueReferences.torque]),
    recordedVrs: new Uint32Array(RECORDED.map((name) => fmu.valueReferences[name])),
    columns: Object.fromEntries(RESULT_COLUMNS.map((name) => [name, new Float64Array(time.length)])),
  };
}

/** The run's columns, its time filled in, once the instance is terminated and dropped. */
function finished(instance, columns, time) {
  columns.time.set(time);
  instance.terminate();
  instance[Symbol.dispose]?.();
  return columns;
}

/**
 * Run a schedule through the FMU's co-simulation export (the transpiled module's
 * instantiate() result); fmu is {instantiationToken, valueReferences: {torque, theta, omega, alpha}}.
 * Returns the columns of RESULT_COLUMNS, one row per communication point.
 */
export function runCoSimulation(exports, fmu, plan, messages = []) {
  const { CoSimulationInstance } = exports.coSimulation;
  const instance = CoSimulationInstance.instantiateCoSimulation(
    "pendulum", fmu.instantiationToken, "", false, false, false, false, new Uint32Array(0)
  );
  const { time } = plan;
  const { torqueVr, recordedVrs, columns } = initialized(instance, fmu, time, messages);
  const record = (k) => {
    const values = call("getFloat64", messages, () => instance.getFloat64(recordedVrs));
    RECORDED.forEach((name, i) => (columns[name][k] = values[i]));
  };
  const torque = new Float64Array(1);
  for (let k = 0; k < time.length - 1; k += 1) {
    torque[0] = plan.torque[k];
    checked(instance.setFloat64(torqueVr, torque), `setFloat64 at t = ${time[k]}`, messages);
    record(k);
    call(`doStep at t = ${time[k]}`, messages, () => instance.doStep(time[k], time[k + 1] - time[k], true));
  }
  record(time.length - 1);
  return finished(instance, columns, time);
}

/** The state a classic Runge-Kutta step of size h reaches from x at t, derivatives(t, x) at each stage. */
export function rungeKuttaStep(derivatives, t, x, h) {
  const k1 = derivatives(t, x);
  const k2 = derivatives(t + h / 2, x.map((xi, i) => xi + (h / 2) * k1[i]));
  const k3 = derivatives(t + h / 2, x.map((xi, i) => xi + (h / 2) * k2[i]));
  const k4 = derivatives(t + h, x.map((xi, i) => xi + h * k3[i]));
  return x.map((xi, i) => xi + (h / 6) * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]));
}

/**
 * Run a schedule through the FMU's model-exchange export, integrated by classic Runge-Kutta in
 * `substeps` equal steps per communication step (the torque held over each), a host's own
 * solver: the columns of RESULT_COLUMNS, one row per communication point.
 */
export function runModelExchange(exports, fmu, plan, substeps, messages = []) {
  const { ModelExchangeInstance } = exports.modelExchange;
  const instance = ModelExchangeInstance.instantiateModelExchange("pendulum", fmu.instantiationToken, "", false, false);
  const { time } = plan;
  const { torqueVr, recordedVrs, columns } = initialized(instance, fmu, time, messages);
  call("updateDiscreteStates", messages, () => instance.updateDiscreteStates());
  checked(instance.enterContinuousTimeMode(), "enterContinuousTimeMode", messages);
  let states = Array.from(call("getContinuousStates", messages, () => instance.getContinuousStates()));
  const derivatives = (t, x) => {
    checked(instance.setTime(t), `setTime(${t})`, messages);
    checked(instance.setContinuousStates(new Float64Array(x)), `setContinuousStates at t = ${t}`, messages);
    return Array.from(call(`getContinuousStateDerivatives at t = ${t}`, messages, () => instance.getContinuousStateDerivatives()));
  };
  const record = (k) => {
    derivatives(time[k], states); // the outputs at the point, from its time and state
    const values = call("getFloat64", messages, () => instance.getFloat64(recordedVrs));
    RECORDED.forEach((name, i) => (columns[name][k] = values[i]));
  };
  for (let k = 0; k < time.length - 1; k += 1) {
    checked(instance.setFloat64(torqueVr, new Float64Array([plan.torque[k]])), `setFloat64 at t = ${time[k]}`, messages);
    record(k);
    const h = (time[k + 1] - time[k]) / substeps;
    for (let j = 0; j < substeps; j += 1) {
      states = rungeKuttaStep(derivatives, time[k] + j * h, states, h);
      checked(instance.setContinuousStates(new Float64Array(states)), "setContinuousStates", messages);
      call("completedIntegratorStep", messages, () => instance.completedIntegratorStep(true));
    }
  }
  record(time.length - 1);
  return finished(instance, columns, time);
}

/** A result as the CSV `pendulum-fmu judge` reads: a header, then a row per point (round-trip digits). */
export function resultCsv(columns) {
  const rows = [RESULT_COLUMNS.join(",")];
  for (let k = 0; k < columns.time.length; k += 1) rows.push(RESULT_COLUMNS.map((name) => String(columns[name][k])).join(","));
  return `${rows.join("\n")}\n`;
}
