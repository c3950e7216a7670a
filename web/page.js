// The docs page's script (docs/browser.md): the visitor's torque signal through the FMU's wasm
// binary, in the browser, theta drawn over the native binary's where the page ships that run
// (native.json), and the result offered as the CSV `pendulum-fmu judge` reads.
import { MAX_CSV_CHARS, fmiCallbacks, parseTorqueCsv, resultCsv, runCoSimulation, schedule } from "./fmu_host.js";

const here = (name) => new URL(name, import.meta.url);
const element = (id) => document.getElementById(id);
const [{ instantiate }, fmu, native] = await Promise.all([
  import(here("fmu.js").href),
  fetch(here("fmu.json")).then((response) => response.json()),
  fetch(here("native.json")).then((response) => response.json()),
]);
let droppedRows = null;
let downloadUrl = null;

function say(text, isError = false) {
  element("wasm-status").textContent = text;
  element("wasm-status").classList.toggle("wasm-error", isError);
}

function number(id) {
  const value = Number(element(id).value);
  if (!Number.isFinite(value)) throw new Error(`${element(id).labels[0].textContent} is not a number`);
  return value;
}

function signal() {
  const kind = element("signal-kind").value;
  if (kind === "constant") return { kind, value: number("torque-value") };
  if (kind === "step") return { kind, before: number("step-before"), after: number("step-after"), at: number("step-at") };
  if (!droppedRows) throw new Error("drop a torque CSV (time,torque) on the field, or choose one");
  return { kind, rows: droppedRows };
}

function sameSchedule(plan, run) {
  return (
    plan.time.length === run.time.length &&
    plan.time.every((t, k) => t === run.time[k]) &&
    plan.torque.every((u, k) => u === run.torque[k])
  );
}

function draw(columns, shipped) {
  const canvas = element("theta-plot");
  const context = canvas.getContext("2d");
  const [width, height, margin] = [canvas.width, canvas.height, 64];
  const series = [columns.theta, ...(shipped ? [shipped.theta] : [])];
  const low = series.reduce((least, values) => values.reduce((a, b) => Math.min(a, b), least), Infinity);
  const high = series.reduce((most, values) => values.reduce((a, b) => Math.max(a, b), most), -Infinity);
  const [t0, t1] = [columns.time[0], columns.time[columns.time.length - 1]];
  const x = (t) => margin + ((t - t0) / (t1 - t0)) * (width - 2 * margin);
  const y = (v) => height - margin - ((v - low) / (high - low || 1)) * (height - 2 * margin);
  // White behind the plot whatever the theme (the site has a dark one).
  context.fillStyle = "#fff";
  context.fillRect(0, 0, width, height);
  context.font = "14px sans-serif";
  context.strokeStyle = "#888";
  context.strokeRect(margin, margin, width - 2 * margin, height - 2 * margin);
  context.fillStyle = "#333";
  for (let i = 0; i <= 4; i += 1) {
    const [t, v] = [t0 + ((t1 - t0) * i) / 4, low + ((high - low) * i) / 4];
    context.fillText(t.toPrecision(3), x(t) - 12, height - margin + 20);
    context.fillText(v.toPrecision(3), 4, y(v) + 4);
  }
  context.fillText("time (s)", width / 2 - 20, height - 10);
  context.fillText("theta (rad)", 4, margin - 16);
  const line = (times, values, colour, dash) => {
    context.beginPath();
    context.setLineDash(dash);
    context.strokeStyle = colour;
    context.lineWidth = 2;
    values.forEach((v, k) => (k ? context.lineTo(x(times[k]), y(v)) : context.moveTo(x(times[k]), y(v))));
    context.stroke();
    context.setLineDash([]);
  };
  line(columns.time, columns.theta, "#1f77b4", []);
  // The legend above the frame, right-aligned, clear of the curves.
  context.textAlign = "right";
  context.fillStyle = "#1f77b4";
  context.fillText("wasm, in this browser", width - margin, margin - 28);
  if (shipped) {
    line(shipped.time, shipped.theta, "#ff7f0e", [8, 6]);
    context.fillStyle = "#ff7f0e";
    context.fillText("- - native linux64 binary (shipped)", width - margin, margin - 10);
  }
  context.textAlign = "left";
}

function run() {
  const messages = [];
  const plan = schedule(signal(), 0, number("stop-time"), number("step-size"));
  const exports = instantiate(undefined, fmiCallbacks((message) => messages.push(message)));
  return Promise.resolve(exports).then((instance) => {
    const started = performance.now();
    const columns = runCoSimulation(instance, fmu, plan, messages);
    const milliseconds = performance.now() - started;
    const last = columns.time.length - 1;
    const [name, shipped] = Object.entries(native).find(([, ran]) => sameSchedule(plan, ran)) ?? [null, null];
    element("theta-final").textContent = `${columns.theta[last]} rad at t = ${columns.time[last]} s`;
    element("theta-final").dataset.value = String(columns.theta[last]);
    const difference = shipped ? shipped.theta.reduce((most, v, k) => Math.max(most, Math.abs(v - columns.theta[k])), 0) : null;
    element("max-difference").textContent = shipped
      ? `${difference === 0 ? "0 rad: the same to the last bit" : `${difference.toExponential(2)} rad`}, the largest |wasm - native| over the run (the ${name} case)`
      : "no native run shipped for this signal";
    element("max-difference").dataset.value = shipped ? String(difference) : "";
    draw(columns, shipped);
    if (downloadUrl) URL.revokeObjectURL(downloadUrl);
    downloadUrl = URL.createObjectURL(new Blob([resultCsv(columns)], { type: "text/csv" }));
    element("download").href = downloadUrl;
    element("download").hidden = false;
    say(`${last} steps in ${milliseconds.toFixed(0)} ms${messages.length ? `; the FMU logged: ${messages.join("; ")}` : ""}`);
  });
}

function readDropped(file) {
  if (file.size > MAX_CSV_CHARS * 4) {
    say(`${file.name}: ${file.size} bytes, too large for a torque CSV`, true);
    return;
  }
  file.text().then((text) => {
    try {
      droppedRows = parseTorqueCsv(text);
      element("signal-kind").value = "csv";
      say(`${file.name}: ${droppedRows.length} rows; set the stop time, then run`);
    } catch (error) {
      droppedRows = null;
      say(`${file.name}: ${error.message}`, true);
    }
  });
}

element("torque-file").addEventListener("change", (event) => readDropped(event.target.files[0]));
element("drop-zone").addEventListener("dragover", (event) => event.preventDefault());
element("drop-zone").addEventListener("drop", (event) => {
  event.preventDefault();
  readDropped(event.dataTransfer.files[0]);
});
element("run").addEventListener("click", () => {
  say("running...");
  setTimeout(() => {
    try {
      run().catch((error) => say(error.message, true));
    } catch (error) {
      say(error.message, true);
    }
  });
});
element("run").disabled = false;
say(`ready: ${fmu.modelIdentifier}.wasm loaded`);
