// Drives `fieldrig stem-ui` in Debian's headless Chromium through Playwright: checks the API's
// 4xx answers to bad requests, loads the session's page, zooms to the stem, clicks the four
// points as a person would, reads the diameter, saves two repeats under one label, checks the
// table of mean and SD, and takes a screenshot.
//   node stem_ui_browser.cjs BASE_URL OUT_DIR CASE_JSON
// CASE_JSON: {"session": name, "repeats": [[x1,y1,…,x4,y4], …], "label": "…"}.
// Prints one JSON line with what it read; exits non-zero on the first failed check.
"use strict";
const http = require("node:http");
const path = require("node:path");
const { chromium } = require("playwright-core");

const [baseUrl, outDir, caseJson] = process.argv.slice(2);
const testCase = JSON.parse(caseJson);

function check(condition, message) {
  if (!condition) throw new Error("check failed: " + message);
}

// A raw request (no URL normalisation, so "/../" reaches the server as written).
function rawRequest(method, target, body) {
  const url = new URL(baseUrl);
  return new Promise((resolve, reject) => {
    const request = http.request({ host: url.hostname, port: url.port, method, path: target,
                                   headers: body ? { "Content-Type": "application/json" } : {} },
      (response) => {
        let data = "";
        response.on("data", (chunk) => (data += chunk));
        response.on("end", () => resolve({ status: response.statusCode, body: data }));
      });
    request.on("error", reject);
    if (body) request.write(body);
    request.end();
  });
}

async function checkBadRequests() {
  const s = encodeURIComponent(testCase.session);
  const points = JSON.stringify(testCase.repeats[0]);
  const cases = [
    ["GET", "/api/sessions/no-such-session/measurements", null, 404, "unknown session"],
    ["GET", "/../../etc/passwd", null, 400, "path traversal"],
    ["GET", "/api/sessions/" + s + "/sets/0/%2e%2e/left.png", null, 400, "path traversal"],
    ["GET", "/api/sessions/" + s + "/sets/999/bottom/left.png", null, 404, "has no set"],
    ["GET", "/api/sessions/" + s + "/sets/zero/bottom/left.png", null, 400, "not a set index"],
    ["GET", "/api/sessions/" + s + "/sets/0/nohead/left.png", null, 404, "has no head"],
    ["POST", "/api/sessions/" + s + "/measure", "{not json", 400, "not a JSON object"],
    ["POST", "/api/sessions/" + s + "/measure",
     '{"set":0,"head":"bottom","points":[1,2,3,"x",5,6,7,8]}', 400, "points[3]"],
    ["POST", "/api/sessions/" + s + "/measure", '{"set":0,"head":"bottom","points":[1,2,3]}',
     400, "8 numbers"],
    ["POST", "/api/sessions/" + s + "/measurements",
     '{"set":0,"head":"bottom","points":' + points + "}", 400, "label"],
  ];
  for (const [method, target, body, status, text] of cases) {
    const response = await rawRequest(method, target, body);
    check(response.status === status,
          `${method} ${target}: status ${response.status}, expected ${status}: ${response.body}`);
    check(response.body.includes(text), `${method} ${target}: "${text}" not in ${response.body}`);
  }
  return cases.length;
}

async function clickPoints(page, points) {
  const xs = [points[0], points[2], points[4], points[6]];
  const ys = [points[1], points[3], points[5], points[7]];
  const cx = xs.reduce((a, b) => a + b) / 4, cy = ys.reduce((a, b) => a + b) / 4;
  // Zoom in on the stem segment as a person would (6 canvas px per image px).
  await page.evaluate(([x, y]) => window.stemUi.zoomTo(x, y, 6), [cx, cy]);
  for (let i = 0; i < 4; ++i) {
    const at = await page.evaluate(([x, y]) => window.stemUi.imageToClient(x, y), [xs[i], ys[i]]);
    await page.mouse.click(at.x, at.y);
  }
}

(async () => {
  const badRequests = await checkBadRequests();
  const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", headless: true,
                                          args: ["--no-sandbox"] });
  try {
    const page = await browser.newPage({ viewport: { width: 1600, height: 1000 } });
    const pageErrors = [];
    page.on("pageerror", (error) => pageErrors.push(error.message));
    await page.goto(baseUrl);
    await page.waitForSelector("body[data-ready=yes]", { timeout: 20000 });
    const diameters = [];
    const elapsed = [];
    for (const points of testCase.repeats) {
      await clickPoints(page, points);
      await page.waitForFunction(() => /^[0-9.]+$/.test(document.getElementById("diameter").textContent),
                                 null, { timeout: 10000 });
      diameters.push(Number(await page.textContent("#diameter")));
      elapsed.push(await page.evaluate(() => window.stemUi.state.result.elapsed_ms));
      const ncc = Number(await page.textContent("#ncc"));
      check(ncc > 0.5, "NCC shown " + ncc);
      await page.fill("#label", testCase.label);
      const rowsBefore = await page.locator("#measurements tbody tr").count();
      await page.click("#save");
      await page.waitForFunction((n) => document.querySelectorAll("#measurements tbody tr").length === n,
                                 rowsBefore + 1, { timeout: 10000 });
    }
    const summary = await page.$$eval("#summary tbody tr",
                                      (rows) => rows.map((r) => [...r.cells].map((c) => c.textContent)));
    await page.screenshot({ path: path.join(outDir, "stem_ui.png"), fullPage: true });
    check(pageErrors.length === 0, "page errors: " + pageErrors.join("; "));
    console.log(JSON.stringify({ bad_requests_checked: badRequests, diameters, elapsed_ms: elapsed,
                                 summary }));
  } finally {
    await browser.close();
  }
})().catch((error) => {
  console.error(error.stack || String(error));
  process.exit(1);
});
