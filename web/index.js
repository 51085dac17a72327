// The page's script: checks what the browser has, starts the viewer (hadou_web.js, made by
// wasm-bindgen), fills the preset list and hands dropped or opened files to the viewer, each
// checked against its size limit before it is read.
import init, * as hadou from "./hadou_web.js";

const byId = (id) => document.getElementById(id);
const status = byId("hadou-status");
const message = byId("hadou-message");
const testMode = new URLSearchParams(location.search).get("test") === "1";

function fail(text) {
  status.textContent = "";
  message.textContent = text;
  byId("hadou-test-error").textContent = text;
}

// What the browser lacks, in words, or "" when it has WebGPU or WebGL2.
function lacking() {
  const webgpu = "gpu" in navigator;
  let webgl2 = false;
  try {
    webgl2 = !!document.createElement("canvas").getContext("webgl2");
  } catch (_) {
    webgl2 = false;
  }
  if (webgpu || webgl2) return "";
  const secure = window.isSecureContext ? "" : " (WebGPU needs a secure page: https:// or http://localhost)";
  return "This browser has neither WebGPU (navigator.gpu" + secure + ") nor WebGL2, and hadou draws with one of them. " +
    "Chrome or Edge 113+, Firefox 141+ or Safari 26+ have WebGPU; most browsers since 2017 have WebGL2 " +
    "(check that hardware acceleration is on).";
}

// The WebGPU adapter's vendor and architecture ("google swiftshader"), for the status line: the
// adapter's description, which is all wgpu reports, is often empty.
async function webgpuAdapter() {
  try {
    const adapter = navigator.gpu && await navigator.gpu.requestAdapter();
    const info = adapter && adapter.info;
    return info ? [info.vendor, info.architecture, info.description].filter((s) => s).join(" ") : "";
  } catch (_) {
    return "";
  }
}

async function takeFiles(list) {
  hadou.drop_begin();
  for (const file of list) {
    // Refused by size (or kind) before a byte is read.
    const why = hadou.refuse_file(file.name, file.size);
    if (why) {
      hadou.drop_refused(why);
      continue;
    }
    hadou.drop_file(file.name, new Uint8Array(await file.arrayBuffer()));
  }
  hadou.drop_end();
}

function installDrop() {
  const hint = byId("hadou-drop-hint");
  // Capture on the window, so the canvas's own handlers never read the files first.
  window.addEventListener("dragover", (e) => {
    e.preventDefault();
    e.stopPropagation();
    hint.hidden = false;
  }, true);
  window.addEventListener("dragleave", (e) => {
    if (e.relatedTarget === null) hint.hidden = true;
  }, true);
  window.addEventListener("drop", (e) => {
    e.preventDefault();
    e.stopPropagation();
    hint.hidden = true;
    if (e.dataTransfer && e.dataTransfer.files.length) takeFiles(e.dataTransfer.files);
  }, true);
  const open = byId("hadou-open");
  open.addEventListener("change", () => {
    if (open.files.length) takeFiles(open.files);
    open.value = "";
  });
}

async function main() {
  const lacks = lacking();
  if (lacks) return fail(lacks);
  await init();
  const select = byId("hadou-presets");
  const wanted = (new URLSearchParams(location.search).get("scene") || "kamehameha").replace(/\.toml$/, "");
  for (const name of hadou.preset_names()) {
    const option = document.createElement("option");
    option.value = option.textContent = name;
    option.selected = name === wanted;
    select.appendChild(option);
  }
  select.addEventListener("change", () => hadou.open_preset(select.value));
  // The page's functions for scripts and tests (drop_begin/drop_file/drop_end, open_preset, …).
  window.hadou = hadou;
  installDrop();
  // Only test mode names the adapter (its report says what drew the frame): some browsers give
  // one WebGPU adapter per page, and the viewer's graphics set-up asks for it next.
  await hadou.start("hadou-canvas", testMode ? await webgpuAdapter() : "");
}

main().catch((e) => fail("hadou could not start: " + (e && e.message ? e.message : e) + (testMode ? "" : " (see the console)")));
