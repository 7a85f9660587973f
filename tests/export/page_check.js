// Opens a page in headless Chromium (Debian's, through playwright-core) and takes pictures of it:
//   node page_check.js web URL [EMPTY] OUTDIR      MuJoCo's web viewer: shots after 20 s and 23 s of live simulation
//                                                  (and of the viewer at the address EMPTY after 20 s); the
//                                                  environment's CLICKS ("x,y x,y") are clicked between the two,
//                                                  each confirmed on stdin (below)
//   node page_check.js html FILE EMPTY OUTDIR T1 T2   an exported page paused at T1 and T2 s (by the slider), then
//                                                     the page EMPTY (the same without the creature) at T1
// Prints one JSON line: {"errors": [console errors and page errors], "shots": [png paths],
// "network": [every address asked for other than data:, file: and blob:], ...}.
const { chromium } = require("playwright-core");
const path = require("path");
(async () => {
  const args = process.argv.slice(2);
  const mode = args.shift(), target = args.shift(), empty = args.length > 1 ? args.shift() : null;
  const [outdir, ...times] = args;
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox"],
  });
  const page = await browser.newPage({ viewport: { width: 640, height: 480 } });
  // a screenshot of a page that draws every frame in software WebGL waits for a frame: on a loaded machine (the full
  // suite on 2 cores) that took over Playwright's default 30 s once, so each wait may take up to 2 minutes
  const SLOW_MS = 120000;
  page.setDefaultTimeout(SLOW_MS);
  if (process.env.THROTTLE) { // a slow machine, for trying this script: the page's CPU slowed this many times
    const cdp = await page.context().newCDPSession(page);
    await cdp.send("Emulation.setCPUThrottlingRate", { rate: Number(process.env.THROTTLE) });
  }
  const errors = [];
  page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
  page.on("pageerror", (e) => errors.push(String(e)));
  const network = []; // what the page asked of anything but itself
  page.on("request", (r) => { if (!/^(data|file|blob):/.test(r.url())) network.push(r.url()); });
  const shots = [];
  const shot = async (name, locator) => {
    const file = path.join(outdir, name);
    await (locator || page).screenshot({ path: file });
    shots.push(file);
  };
  const result = { errors, shots, network };
  try {
    if (mode === "html") {
      await page.goto("file://" + path.resolve(target));
      await page.waitForSelector("body[data-loaded=yes]", { timeout: 60000 });
      const viewer = page.locator("#run");
      await page.click("#play"); // pause
      result.paused = await page.$eval("#run", (e) => e.paused);
      result.duration = await page.$eval("#run", (e) => e.duration);
      result.appended = await page.$eval("#run", (e) => e.appendedAnimations || []); // a crowd's shared cycles
      for (const t of times) {
        await page.$eval("#scrub", (e, v) => { e.value = v; e.dispatchEvent(new Event("input")); }, t);
        await page.waitForTimeout(1500);
        result["time_" + t] = await page.$eval("#run", (e) => e.currentTime);
        await shot("t" + t + ".png", viewer);
      }
      if (empty) { // the empty scene: the same page, camera and time, without the creature
        await page.goto("file://" + path.resolve(empty));
        await page.waitForSelector("body[data-loaded=yes]", { timeout: 60000 });
        await page.click("#play");
        await page.$eval("#scrub", (e, v) => { e.value = v; e.dispatchEvent(new Event("input")); }, times[0]);
        await page.waitForTimeout(1500);
        await shot("empty.png", page.locator("#run"));
      }
    } else {
      // MuJoCo's web viewer: TARGET and, in a second tab, EMPTY (the same scene without the creature)
      const pages = [page];
      if (empty) {
        const other = await browser.newPage({ viewport: { width: 640, height: 480 } });
        other.setDefaultTimeout(SLOW_MS);
        other.on("console", (m) => { if (m.type() === "error") errors.push("empty: " + m.text()); });
        other.on("pageerror", (e) => errors.push("empty: " + String(e)));
        pages.push(other);
      }
      await Promise.all(pages.map((p, i) => p.goto(i === 0 ? target : empty)));
      // the WASM client downloads and compiles first: wait until the picture changes from one second to the next
      // (the scene drawn and running), at most 30 s
      const blank = await page.screenshot();
      let last = blank;
      for (let waited = 0; waited < 30000; waited += 1000) {
        await page.waitForTimeout(1000);
        const now = await page.screenshot();
        if (!now.equals(blank) && !now.equals(last) && waited >= 3000) break;
        last = now;
      }
      await page.waitForTimeout(1000);
      await shot("live1.png");
      if (empty) {
        const file = path.join(outdir, "empty.png");
        await pages[1].screenshot({ path: file });
        shots.push(file);
      }
      // buttons drawn in the canvas, pressed one by one: the page sends the mouse to the server once a frame and
      // the server reads it once a frame of its own, so on a loaded machine a press can fall between two frames and
      // be lost. After each press this prints {"pressed": i} and reads a line: "again" presses it once more, anything
      // else goes on (the caller watches the server for the press's effect); with no reader, stdin's end goes on.
      const clicks = (process.env.CLICKS || "").split(" ").filter(Boolean);
      const reader = clicks.length ? require("readline").createInterface({ input: process.stdin }) : null;
      const lines = reader && reader[Symbol.asyncIterator]();
      let hold = 300; // ms, longer at each try of the same button
      for (let i = 0; i < clicks.length; i++) {
        const [x, y] = clicks[i].split(",").map(Number);
        await page.mouse.move(x, y);
        await page.waitForTimeout(hold);
        await page.mouse.down();
        await page.waitForTimeout(hold);
        await page.mouse.up();
        console.log(JSON.stringify({ pressed: i, hold_ms: hold }));
        const answer = await lines.next();
        const again = !answer.done && answer.value.trim() === "again";
        if (again) i--;
        hold = again ? hold * 3 : 300;
      }
      if (reader) reader.close();
      await page.waitForTimeout(3000);
      await shot("live2.png");
    }
  } catch (e) {
    errors.push("check: " + String(e));
  }
  await browser.close();
  console.log(JSON.stringify(result));
})();
