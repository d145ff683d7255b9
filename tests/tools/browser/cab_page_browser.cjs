// Watches fieldrigd's in-cab page in Debian's headless Chromium (Playwright) while the test
// (tests/tools/cab_page_browser_test.cpp) replays a drive with a GPS gap, ends the daemon and
// starts another on the same port. It only looks, as the operator does: every 100 ms it reads
// each dot's state and its colour as drawn, the alarms and the connection banner, and records
// when each changed (wall-clock ms; the dots in the first run only). Screenshots at three moments into OUT_DIR.
//   node cab_page_browser.cjs URL OUT_DIR CASE_JSON
// CASE_JSON: {"locations": 12, "missed": "R01P03", "timeout_s": 240}.
// Prints a JSON line when it saw the daemon go, and at the end one with all it saw; exits
// non-zero when a moment never came.
"use strict";
const path = require("node:path");
const { chromium } = require("playwright-core");

const [url, outDir, caseJson] = process.argv.slice(2);
const testCase = JSON.parse(caseJson);
const deadline = Date.now() + (testCase.timeout_s || 240) * 1000;

// What the page shows, read from its DOM and computed styles.
function look() {
  const dots = [...document.querySelectorAll("#dots circle")].map((dot) => [
    dot.dataset.id, dot.dataset.state, getComputedStyle(dot).fill]);
  const alarms = [...document.querySelectorAll("#alarms .alarm")].map((item) => ({
    kind: item.dataset.kind, time: item.dataset.time,
    text: item.innerText }));
  const badge = document.getElementById("connection");
  return { dots, alarms, connection: badge.dataset.state,
           note: document.getElementById("connection-note").textContent,
           row: document.getElementById("row-name").textContent,
           tractor: document.getElementById("tractor").getAttribute("visibility"),
           gauge: document.getElementById("gauge").dataset.level,
           gps_fix: document.getElementById("gps-fix").textContent,
           thumbnails: [...document.querySelectorAll("#thumbnails img")].map(
             (image) => image.complete ? image.naturalWidth : -1),
           banner: document.getElementById("alarm-banner").innerText,
           banner_visible: getComputedStyle(document.getElementById("alarm-banner")).display !== "none" };
}

(async () => {
  const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", headless: true,
                                          args: ["--no-sandbox"] });
  const seen = { transitions: {}, alarms: {}, screenshots: [] };
  try {
    // A small screen: a tablet in the cab.
    const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
    const errors = [];
    page.on("pageerror", (error) => errors.push(String(error)));
    const started = Date.now();
    await page.goto(url, { waitUntil: "load" });
    seen.load_ms = Date.now() - started;
    await page.waitForFunction((n) => document.querySelectorAll("#dots circle").length === n &&
                                      document.getElementById("connection").dataset.state ===
                                        "connected", testCase.locations, { timeout: 60000 });
    seen.ready_ms = Date.now() - started;

    let moment = 0;  // 0 first plots, 1 GPS loss and the missed red dot, 2 lost, 3 regained
    const last = {};
    while (moment < 4) {
      if (Date.now() > deadline) throw new Error(`moment ${moment} never came: ` + JSON.stringify(seen));
      const now = Date.now();
      const view = await page.evaluate(look);
      // The dots' changes in the first run (until its daemon is gone).
      for (const [id, state, fill] of seen.lost_seen_at ? [] : view.dots) {
        const key = state + "|" + fill;
        if (last[id] !== key) {
          (seen.transitions[id] = seen.transitions[id] || []).push([state, fill, now]);
          last[id] = key;
        }
      }
      for (const alarm of view.alarms) {
        if (!seen.alarms[alarm.kind])
          seen.alarms[alarm.kind] = { seen_at: now, time: alarm.time, text: alarm.text };
      }
      // The banner at the top: the first time it showed the GPS loss.
      if (view.banner_visible && view.banner.includes("gps_lost") && !seen.gps_lost_banner) {
        seen.gps_lost_banner = { seen_at: now, text: view.banner };
      }
      seen.last_view = view;
      const missed = view.dots.find(([id]) => id === testCase.missed);
      if (moment === 0 && view.dots.some(([, state]) => state !== "pending")) {
        await page.screenshot({ path: path.join(outDir, "cab_page_1_first_plots.png"), fullPage: true });
        seen.screenshots.push("cab_page_1_first_plots.png");
        moment = 1;
      } else if (moment === 1 && seen.alarms.gps_lost && missed && missed[1] === "missed") {
        await page.screenshot({ path: path.join(outDir, "cab_page_2_gps_lost_missed.png"), fullPage: true });
        seen.screenshots.push("cab_page_2_gps_lost_missed.png");
        seen.first_run_view = view;
        moment = 2;
      } else if (moment === 2 && view.connection === "lost") {
        seen.lost_seen_at = now;
        seen.lost_note = view.note;
        console.log(JSON.stringify({ lost_seen_at: now }));  // the test starts the next daemon
        moment = 3;
      } else if (moment === 3 && view.connection === "connected" &&
                 view.dots.some(([, state]) => state !== "pending")) {
        // The second daemon's run: its own first plots on the page.
        seen.regained_seen_at = now;
        seen.regained_note = view.note;
        await page.screenshot({ path: path.join(outDir, "cab_page_3_reconnected.png"), fullPage: true });
        seen.screenshots.push("cab_page_3_reconnected.png");
        moment = 4;
      }
      await new Promise((resolve) => setTimeout(resolve, 100));
    }
    seen.page_errors = errors;
    console.log(JSON.stringify(seen));
  } finally {
    await browser.close();
  }
})().catch((error) => {
  console.error(error.stack || String(error));
  process.exit(1);
});
