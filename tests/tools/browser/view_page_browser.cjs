// Opens `fieldrig view` (the in-cab page on a recorded session) in Debian's headless Chromium
// (Playwright) for tests/tools/view_page_browser_test.cpp: reads each dot's state and colour as
// drawn and the plots table, clicks the processed plot's dot, follows its stem link into the stem
// tool and reads which set the stem page opened. Screenshot into OUT_DIR.
//   node view_page_browser.cjs VIEW_URL OUT_DIR CASE_JSON
// CASE_JSON: {"processed": "plot-1"}. Prints one JSON line with what it saw.
"use strict";
const path = require("node:path");
const { chromium } = require("playwright-core");

const [url, outDir, caseJson] = process.argv.slice(2);
const testCase = JSON.parse(caseJson);

(async () => {
  const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", headless: true,
                                          args: ["--no-sandbox"] });
  const seen = {};
  try {
    const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
    const errors = [];
    page.on("pageerror", (error) => errors.push(String(error)));
    await page.goto(url);
    // The session's status and its plots have arrived: the table is filled.
    await page.waitForFunction(() => document.body.dataset.mode === "session" &&
      document.querySelectorAll("#plots tbody tr").length > 0, null, { timeout: 60000 });
    seen.dots = await page.evaluate(() => [...document.querySelectorAll("#dots circle")].map(
      (dot) => [dot.dataset.id, dot.dataset.state, getComputedStyle(dot).fill]));
    seen.connection = await page.textContent("#connection");
    seen.gps_visible = await page.isVisible("#gps-section");
    seen.rows = await page.evaluate(() => [...document.querySelectorAll("#plots tbody tr")].map(
      (row) => [...row.cells].map((cell) => cell.textContent)));
    await page.click(`#dots circle[data-id="${testCase.processed}"]`);
    seen.selected = await page.innerText("#last-plot");
    const link = page.locator("#last-plot a");
    seen.stem_href = await link.getAttribute("href");
    await page.screenshot({ path: path.join(outDir, "view-session.png"), fullPage: true });
    // The stem tool the link names (the test runs it): the page opens the plot's set.
    const stem = await browser.newPage({ viewport: { width: 1000, height: 700 } });
    await stem.goto(seen.stem_href);
    await stem.waitForFunction(() => window.stemUi && window.stemUi.state &&
                               window.stemUi.state.set !== undefined &&
                               window.stemUi.state.set !== null, null, { timeout: 60000 });
    seen.stem_set = await stem.evaluate(() => window.stemUi.state.set);
    seen.stem_set_select = await stem.inputValue("#set");
    seen.errors = errors;
  } finally {
    await browser.close();
  }
  console.log(JSON.stringify(seen));
})().catch((error) => { console.error(error); process.exit(1); });
