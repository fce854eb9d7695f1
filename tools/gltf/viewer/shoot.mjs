// node tools/gltf/viewer/shoot.mjs MODEL.glb OUT_DIR T1 [T2 ...]
// Serves viewer.html, three.js and MODEL.glb on localhost, opens them in
// headless Chromium (CHROMIUM, default /usr/bin/chromium), and for each
// time writes OUT_DIR/pose-<t>.png and every node's world position to
// OUT_DIR/positions.json ({"<t>": {"<node>": [x, y, z]}}).
import fs from "node:fs";
import http from "node:http";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

const [model, out, ...times] = process.argv.slice(2);
if (!model || !out || times.length === 0) {
  console.error("usage: node shoot.mjs MODEL.glb OUT_DIR T1 [T2 ...]");
  process.exit(2);
}
const here = path.dirname(fileURLToPath(import.meta.url));
const types = { ".html": "text/html", ".js": "text/javascript", ".glb": "model/gltf-binary" };
const server = http.createServer((req, res) => {
  const url = decodeURIComponent(new URL(req.url, "http://x").pathname);
  let file;
  if (url === "/" || url === "/viewer.html") file = path.join(here, "viewer.html");
  else if (url === "/model.glb") file = path.resolve(model);
  else if (url.startsWith("/three/")) file = path.join(here, "node_modules", url.slice(1));
  if (!file || !fs.existsSync(file)) {
    res.writeHead(404).end();
    return;
  }
  res.writeHead(200, { "content-type": types[path.extname(file)] ?? "application/octet-stream" });
  fs.createReadStream(file).pipe(res);
});
await new Promise((r) => server.listen(0, "127.0.0.1", r));
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox"],
});
try {
  const page = await browser.newPage({ viewport: { width: 720, height: 720 } });
  page.on("console", (m) => console.log(`page: ${m.text()}`));
  page.on("pageerror", (e) => console.log(`page error: ${e.message}`));
  await page.goto(`http://127.0.0.1:${server.address().port}/viewer.html`);
  await page.waitForFunction(() => window.ready, null, { timeout: 60000 });
  const info = await page.evaluate(() => window.ready);
  console.log(`loaded ${model}: ${info.nodes} nodes, ${info.duration} s`);
  fs.mkdirSync(out, { recursive: true });
  const positions = {};
  for (const t of times) {
    positions[t] = await page.evaluate((t) => window.shoot(t), Number(t));
    const png = path.join(out, `pose-${t}.png`);
    await page.screenshot({ path: png });
    console.log(`wrote ${png}`);
  }
  fs.writeFileSync(path.join(out, "positions.json"), JSON.stringify(positions));
} finally {
  await browser.close();
  server.close();
}
