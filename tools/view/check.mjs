// node tools/view/check.mjs PAGE.html OUT_DIR T1 [T2 ...]
//
// Opens a page that `tcb view` wrote in headless Chromium (CHROMIUM, default
// /usr/bin/chromium; playwright-core drives it, no browser download), works
// it through its controls as a person would, and prints one JSON report on
// stdout for a test to judge (crates/tcb-cli/tests/view.rs):
//
// - at each time Ti: the timeline dragged to the frame nearest Ti, a
//   screenshot OUT_DIR/shot-<Ti>.png (the 3D view; the whole page for a
//   clip with no skeleton), the joints' positions as drawn, the root's
//   place on the canvas, and the figure's pixels (the orange bones) found
//   in the screenshot: how many, their centroid and bounding box;
// - playback: Play pressed at 2x for about 0.6 s, then Pause;
// - picking: a click on a joint in the 3D view, and a choice in the
//   "curves of" list, and what the page showed for each;
// - orbit: where the joint the drag moved most is drawn
//   before and after a drag across the view;
// - every request the page made that was not for itself or a blob (a
//   self-contained page makes none), and every console error.
//
// The page is opened from a file:// URL, as a user would open it.
import fs from "node:fs";
import path from "node:path";
import { pathToFileURL } from "node:url";
import { chromium } from "playwright-core";
import { PNG } from "pngjs";

const [page_, out, ...times] = process.argv.slice(2);
if (!page_ || !out || times.length === 0) {
  console.error("usage: node tools/view/check.mjs PAGE.html OUT_DIR T1 [T2 ...]");
  process.exit(2);
}
fs.mkdirSync(out, { recursive: true });

/** The figure's pixels in a PNG: the bones' orange (0xd04020, lit). */
function figurePixels(file) {
  const png = PNG.sync.read(fs.readFileSync(file));
  let n = 0;
  let sx = 0;
  let sy = 0;
  let minX = Infinity;
  let maxX = -Infinity;
  let minY = Infinity;
  let maxY = -Infinity;
  for (let y = 0; y < png.height; y++) {
    for (let x = 0; x < png.width; x++) {
      const i = 4 * (y * png.width + x);
      const [r, g, b] = [png.data[i], png.data[i + 1], png.data[i + 2]];
      if (r > 90 && r > 1.6 * g && r > 1.8 * b) {
        n++;
        sx += x;
        sy += y;
        minX = Math.min(minX, x);
        maxX = Math.max(maxX, x);
        minY = Math.min(minY, y);
        maxY = Math.max(maxY, y);
      }
    }
  }
  return n === 0
    ? { pixels: 0, width: png.width, height: png.height }
    : { pixels: n, cx: sx / n, cy: sy / n, minX, maxX, minY, maxY, width: png.width, height: png.height };
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: [
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-quic",
  ],
});
const report = { page: path.resolve(page_), requests: [], errors: [], shots: [] };
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 }, deviceScaleFactor: 1 });
  page.on("console", (m) => {
    if (m.type() === "error") report.errors.push(`console: ${m.text()}`);
  });
  page.on("pageerror", (e) => report.errors.push(`page: ${e.message}`));
  const self = pathToFileURL(path.resolve(page_)).href;
  page.on("request", (r) => {
    const u = r.url();
    if (u !== self && !u.startsWith("blob:") && !u.startsWith("data:")) report.requests.push(u);
  });
  await page.goto(self);
  await page.waitForFunction(() => window.tcbView && window.tcbView.ready, null, { timeout: 60000 });
  const info = await page.evaluate(() => {
    const v = window.tcbView;
    return { hasSkeleton: v.hasSkeleton, root: v.root, joints: v.joints, groups: v.groups, frames: v.times.length };
  });
  Object.assign(report, info);
  report.stageVisible = await page.locator("#stage").isVisible();
  const drawn = () => page.evaluate(() => window.tcbView.drawn());

  for (const t of times) {
    // Drag the timeline to the frame nearest t.
    await page.evaluate((t) => {
      const ts = window.tcbView.times;
      let best = 0;
      for (let i = 1; i < ts.length; i++) if (Math.abs(ts[i] - t) < Math.abs(ts[best] - t)) best = i;
      const tl = document.getElementById("timeline");
      tl.value = String(best);
      tl.dispatchEvent(new Event("input", { bubbles: true }));
    }, Number(t));
    await drawn();
    const png = path.join(out, `shot-${t}.png`);
    if (info.hasSkeleton) await page.locator("#view").screenshot({ path: png });
    else await page.screenshot({ path: png, fullPage: true });
    const shot = await page.evaluate(() => ({
      state: window.tcbView.state(),
      positions: window.tcbView.jointPositions(),
      root: window.tcbView.root ? window.tcbView.project(window.tcbView.root) : null,
      timeText: document.getElementById("time").textContent,
    }));
    report.shots.push({ asked: Number(t), png, ...shot, figure: info.hasSkeleton ? figurePixels(png) : null });
    console.error(`wrote ${png}`);
  }

  // Playback at 2x for about 0.6 s.
  const before = await page.evaluate(() => window.tcbView.state().time);
  await page.selectOption("#speed", "2");
  await page.click("#play");
  await page.waitForTimeout(600);
  const playing = await page.evaluate(() => window.tcbView.state());
  await page.click("#play");
  const paused = await page.evaluate(() => window.tcbView.state());
  report.playback = { before, playing, paused, button: await page.textContent("#play") };

  // Picking: a click on a joint in the view, then a choice in the list.
  report.pick = {};
  if (info.hasSkeleton) {
    const name = info.joints.find((j) => /LeftFoot$|Head$/.test(j)) ?? info.joints[info.joints.length - 1];
    const p = await page.evaluate((n) => window.tcbView.project(n), name);
    const box = await page.locator("#view").boundingBox();
    await page.mouse.click(box.x + p.x, box.y + p.y);
    await drawn();
    report.pick.clicked = name;
    report.pick.afterClick = await page.evaluate(() => window.tcbView.state());
  }
  // Orbit: a drag across the view turns the camera about its target. The
  // joint reported is the one whose drawn position moved most: a joint near
  // the vertical axis through the target (the head, above it) barely moves
  // when the camera turns about that axis, and which joints are there
  // depends on the time playback was paused at (a busy machine pauses it
  // later; watching the joint drawn farthest from the centre once saw one
  // move 13.6 px).
  if (info.hasSkeleton) {
    const box = await page.locator("#view").boundingBox();
    const project = () =>
      page.evaluate((names) => names.map((n) => window.tcbView.project(n)), info.joints);
    const before = await project();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width / 2 - 200, box.y + box.height / 2, { steps: 10 });
    await page.mouse.up();
    await drawn();
    const after = await project();
    let most = 0;
    for (let i = 1; i < info.joints.length; i++) {
      const d = (j) => Math.hypot(after[j].x - before[j].x, after[j].y - before[j].y);
      if (d(i) > d(most)) most = i;
    }
    report.orbit = { joint: info.joints[most], before: before[most], after: after[most] };
  }
  const last = info.groups[info.groups.length - 1];
  await page.selectOption("#joint", { label: last });
  await page.waitForFunction(() => {
    const img = document.getElementById("plot-img");
    return img.complete && img.naturalWidth > 0;
  });
  await drawn();
  report.pick.chosen = last;
  report.pick.afterChoice = await page.evaluate(() => ({
    state: window.tcbView.state(),
    caption: document.getElementById("caption").textContent,
    img: [document.getElementById("plot-img").naturalWidth, document.getElementById("plot-img").naturalHeight],
  }));
  const whole = path.join(out, "page.png");
  await page.screenshot({ path: whole, fullPage: true });
  report.pageShot = whole;
  console.error(`wrote ${whole}`);
} finally {
  await browser.close();
}
process.stdout.write(JSON.stringify(report) + "\n");
