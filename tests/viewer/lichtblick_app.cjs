// Opens a recording in Lichtblick's web app, in headless Chromium, and reports what it shows.
//
//   node lichtblick_app.cjs APP_DIR NODE_MODULES RECORDING LAYOUT TIME OUT_DIR
//
// APP_DIR is a build of Lichtblick's web app (web/.webpack); NODE_MODULES the checkout's
// node_modules (its playwright and serve-handler). The app is served on loopback with LAYOUT as
// its default layout (the placeholder in index.html that Lichtblick's Docker image fills the
// same way), and opens RECORDING through its "remote file" data source (HTTP range requests),
// seeking to TIME (RFC 3339). Written to OUT_DIR: page.png and one PNG per panel, named by its
// id. Printed: one JSON object with the Alerts (formerly Problems) tab's text, its count badge
// and the badge's colour (its most severe alert's: "Error", "Warning", "Info"; null without
// alerts), the text of each panel, the box of each panel's canvas in its PNG and the console's
// errors.
"use strict";
const fs = require("fs");
const http = require("http");
const path = require("path");

const [appDir, nodeModules, recording, layoutFile, time, outDir] = process.argv.slice(2);
const { chromium } = require(path.join(nodeModules, "playwright"));
const serveHandler = require(path.join(nodeModules, "serve-handler"));

const index = fs
  .readFileSync(path.join(appDir, "index.html"), "utf8")
  .replace("/*LICHTBLICK_SUITE_DEFAULT_LAYOUT_PLACEHOLDER*/", fs.readFileSync(layoutFile, "utf8"));

const server = http.createServer((request, response) => {
  const url = new URL(request.url, "http://localhost");
  if (url.pathname === "/" || url.pathname === "/index.html") {
    response.writeHead(200, { "content-type": "text/html" });
    response.end(index);
    return;
  }
  if (url.pathname.startsWith("/recording/")) {
    request.url = url.pathname.slice("/recording".length);
    void serveHandler(request, response, { public: path.dirname(recording) });
    return;
  }
  void serveHandler(request, response, { public: appDir });
});

async function main() {
  await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
  const base = `http://127.0.0.1:${server.address().port}`;
  const browser = await chromium.launch({
    executablePath: process.env.UAVTOOL_CHROMIUM || "/usr/bin/chromium",
    args: [
      "--no-sandbox",
      "--disable-gpu",
      "--disable-quic",
      "--no-first-run",
      "--disable-background-networking",
      "--disable-component-update",
      "--disable-sync",
      "--use-gl=swiftshader",
      "--enable-unsafe-swiftshader",
    ],
  });
  try {
    const page = await browser.newPage({ viewport: { width: 1600, height: 1000 } });
    const errors = [];
    let idle = false;
    page.on("pageerror", (error) => errors.push(`page error: ${error.message}`));
    page.on("console", (message) => {
      if (message.type() === "error") errors.push(message.text());
      if (message.text().includes("Set next state: idle")) idle = true;
    });
    const file = encodeURIComponent(`${base}/recording/${path.basename(recording)}`);
    await page.goto(`${base}/?ds=remote-file&ds.url=${file}&time=${encodeURIComponent(time)}`);
    // The player reports "idle" once it has loaded the file and seeked; then give the panels
    // (the plot loads the whole range in blocks, the 3D panel its model) time to draw.
    for (let waited = 0; !idle && waited < 60_000; waited += 250) {
      await page.waitForTimeout(250);
    }
    await page.waitForTimeout(6_000);
    fs.mkdirSync(outDir, { recursive: true });
    await page.screenshot({ path: path.join(outDir, "page.png") });
    const panels = {};
    const canvases = {};
    for (const panel of await page.locator("[data-testid^='panel-mouseenter-container']").all()) {
      const id = (await panel.getAttribute("data-testid")).split(" ").slice(1).join(" ");
      await panel.screenshot({ path: path.join(outDir, `${id.replace(/[^\w.-]/g, "_")}.png`) });
      panels[id] = await panel.innerText();
      // Where the panel draws (an image panel: its picture, fitted): x, y, width, height in
      // the panel's screenshot.
      const canvas = panel.locator("canvas").first();
      if ((await canvas.count()) > 0) {
        const [outer, inner] = [await panel.boundingBox(), await canvas.boundingBox()];
        canvases[id] = [inner.x - outer.x, inner.y - outer.y, inner.width, inner.height];
      }
    }
    // The tab is "Alerts" in today's Lichtblick, "Problems" in older ones. Its badge counts
    // them, coloured by the most severe (MuiBadge-colorError, -colorWarning or -colorInfo).
    const tab = page.getByTestId("alerts-left").or(page.getByTestId("problems-left"));
    const badge = (await tab.innerText()).replace(/Alerts|Problems/, "").trim();
    const shown = tab.locator(".MuiBadge-badge:not(.MuiBadge-invisible)");
    const severity =
      (await shown.count()) > 0
        ? (/MuiBadge-color(\w+)/.exec(await shown.getAttribute("class"))?.[1] ?? "default")
        : null;
    await tab.click();
    await page.waitForTimeout(500);
    const sidebar = await page.getByTestId("sidebar-left").innerText();
    const problems = sidebar.slice(sidebar.indexOf("Layouts") + "Layouts".length).trim();
    const seen = { idle, badge, severity, problems, panels, canvases, errors };
    process.stdout.write(JSON.stringify(seen) + "\n");
  } finally {
    await browser.close();
    server.close();
  }
}

main().catch((error) => {
  process.stderr.write(`${error.stack || error}\n`);
  process.exit(1);
});
