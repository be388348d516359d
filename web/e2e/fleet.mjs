// SPDX-License-Identifier: GPL-3.0-or-later
// End-to-end test of the fleet view in headless Chromium: a mosquitto broker on a free loopback
// port, two simulated mills publishing to it (`opencnc serve --mqtt`, one of them running the
// bracket program), `opencnc fleet` on the broker; the page shows both machines with their state
// and program, a click on a machine's name opens its own HMI, and the machine killed with SIGKILL
// turns unavailable within the broker's keep-alive. Screenshots land in the artefacts folder.
// Usage: node e2e/fleet.mjs [--opencnc PATH] [--out DIR]
import { spawn } from "node:child_process";
import { mkdtempSync, mkdirSync, rmSync, writeFileSync } from "node:fs";
import { createServer } from "node:net";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { chromium } from "playwright-core";
import { commandLine } from "./cli.mjs";
import { serverUrl, stopServer, waitFor as waitForOn } from "./wait.mjs";

const { repo, opencnc, out } = commandLine("e2e/fleet.mjs");
const data = mkdtempSync(join(tmpdir(), "opencnc-fleet-e2e-"));
const step = (what) => console.log(`fleet e2e: ${what}`);

/** A loopback port nobody listens on now. */
const freePort = () => new Promise((ok) => {
  const s = createServer();
  s.listen(0, "127.0.0.1", () => {
    const { port } = s.address();
    s.close(() => ok(port));
  });
});

const port = await freePort();
// As root, mosquitto would switch to its own user, who may not read the test's folder.
writeFileSync(join(data, "mosquitto.conf"),
  `listener ${port} 127.0.0.1\nallow_anonymous true\npersistence false\n${process.getuid?.() === 0 ? "user root\n" : ""}`);
const broker = spawn("/usr/sbin/mosquitto", ["-c", join(data, "mosquitto.conf")], { stdio: "ignore" });
const mqtt = `mqtt://127.0.0.1:${port}`;
const token = "fleet-e2e-operator-token-0123456789";
const machine = (name, program) => {
  mkdirSync(join(data, name));
  return spawn(opencnc, ["serve", "--machine", join(repo, "configs", "mill-3axis.toml"), "--listen", "127.0.0.1:0",
    "--data", join(data, name), "--static", join(repo, "web/dist"), "--speed", "30", "--device-name", name,
    "--mqtt", mqtt, ...(program ? ["--programs", join(repo, "examples"), "--program", join(repo, "examples", program)] : [])], {
    env: { ...process.env, OPENCNC_OPERATOR_TOKEN: token, OPENCNC_ADMIN_TOKEN: `${token}-admin` },
    stdio: ["ignore", "pipe", "inherit"],
  });
};
const millA = machine("mill-a", "bracket.ngc");
const millB = machine("mill-b");
const fleet = spawn(opencnc, ["fleet", "--broker", mqtt, "--listen", "127.0.0.1:0", "--static", join(repo, "web/dist")],
  { stdio: ["ignore", "pipe", "inherit"] });

let failed = false;
const browser = await chromium.launch({
  executablePath: "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
    "--disable-component-update", "--disable-sync"],
});
const page = await browser.newPage({ viewport: { width: 1300, height: 500 } });
page.on("pageerror", (e) => console.error(`page error: ${e.message}`));
const waitFor = (what, check, ms) => waitForOn(page, what, check, ms);
const cell = (name, id) => page.getByTestId(`machine-${name}`).getByTestId(id).innerText();
const rowCount = (name) => page.getByTestId(`machine-${name}`).count();

try {
  const [urlA, urlB, fleetUrl] = await Promise.all([serverUrl(millA), serverUrl(millB), serverUrl(fleet, "opencnc fleet")]);
  const hmiA = new URL(urlA).origin + "/";
  step("mill-a homes and starts the bracket program");
  const post = (body) => fetch(new URL("/api/v1/commands", hmiA), {
    method: "POST", headers: { Authorization: `Bearer ${token}`, "Content-Type": "application/json" }, body: JSON.stringify(body),
  });
  await post({ kind: "home" });
  await waitFor("mill-a homed", async () => (await (await fetch(new URL("/api/v1/status", hmiA))).json()).all_homed === true);
  const started = await post({ kind: "cycle-start" });
  if (!started.ok) throw new Error(`cycle start answered ${started.status}: ${await started.text()}`);

  step("the fleet view shows both machines");
  await page.goto(fleetUrl);
  await waitFor("two machines", async () => (await rowCount("mill-a")) === 1 && (await rowCount("mill-b")) === 1);
  await waitFor("mill-a running its program", async () =>
    /^(active|wait)/.test(await cell("mill-a", "state")) && (await page.getByTestId("machine-mill-a").innerText()).includes("bracket.ngc"), 30000);
  await waitFor("mill-b, switched off, stopped", async () => (await cell("mill-b", "state")) === "stopped");
  if (!(await page.getByTestId("summary").innerText()).startsWith("2 machines")) throw new Error("the summary does not count 2 machines");
  if (!(await page.getByTestId("broker").innerText()).includes("connected")) throw new Error("the broker is not shown connected");
  await page.screenshot({ path: join(out, "fleet-01-two-machines.png") });

  step("mill-b's spindle turns under a simulated cut: its load shows");
  // 35 N·m on the simulated spindle is 100 % of mill-3axis's rated torque, plus its friction.
  const postB = (body, who = token) => fetch(new URL("/api/v1/commands", new URL(urlB).origin + "/"), {
    method: "POST", headers: { Authorization: `Bearer ${who}`, "Content-Type": "application/json" }, body: JSON.stringify(body),
  });
  for (const body of [{ kind: "machine-on" }, { kind: "mode", mode: "manual" }, { kind: "spindle-on", rpm: 3000 }]) {
    const r = await postB(body);
    if (!r.ok) throw new Error(`mill-b answered ${JSON.stringify(body)} with ${r.status}: ${await r.text()}`);
  }
  const loaded = await postB({ kind: "simulate", event: "spindle-load", torque_nm: 35 }, `${token}-admin`);
  if (!loaded.ok) throw new Error(`the simulated spindle load was answered ${loaded.status}: ${await loaded.text()}`);
  await waitFor("mill-b's spindle loaded", async () => {
    const m = /(\d+) rpm, (\d+) %/.exec(await cell("mill-b", "spindle"));
    return m !== null && Number(m[1]) === 3000 && Number(m[2]) >= 100 && Number(m[2]) <= 110;
  }, 15000);
  step(`mill-b's spindle: ${await cell("mill-b", "spindle")}`);

  step("a click on mill-a opens its own HMI");
  const [hmiPage] = await Promise.all([page.context().waitForEvent("page"), page.getByTestId("machine-mill-a").getByRole("link", { name: "mill-a" }).click()]);
  await hmiPage.waitForLoadState();
  if (hmiPage.url() !== hmiA) throw new Error(`the link opened ${hmiPage.url()}, not ${hmiA}`);
  if (!(await hmiPage.title()).startsWith("opencnc")) throw new Error(`the HMI's title is "${await hmiPage.title()}"`);
  await hmiPage.close();

  step("mill-b killed: unavailable within the keep-alive");
  const killed = Date.now();
  millB.kill("SIGKILL");
  await waitFor("mill-b unavailable", async () => (await cell("mill-b", "state")) === "unavailable", 12000);
  const seconds = (Date.now() - killed) / 1000;
  step(`mill-b unavailable ${seconds.toFixed(1)} s after the kill`);
  if (seconds > 9) throw new Error(`mill-b turned unavailable after ${seconds} s, more than 1.5 keep-alives (7.5 s) and the page's second`);
  if ((await cell("mill-a", "state")) === "unavailable") throw new Error("mill-a turned unavailable too");
  await page.screenshot({ path: join(out, "fleet-02-one-killed.png") });
  step("passed");
} catch (e) {
  failed = true;
  console.error(`fleet e2e: FAILED: ${e.message}`);
  await page.screenshot({ path: join(out, "fleet-failure.png") }).catch(() => {});
} finally {
  await browser.close();
  for (const [name, p] of [["opencnc fleet", fleet], ["mill-a", millA]]) {
    const stop = await stopServer(p);
    if (stop) {
      failed = true;
      console.error(`fleet e2e: FAILED: ${name}: ${stop}`);
    }
  }
  if (millB.exitCode === null && millB.signalCode === null) millB.kill("SIGKILL");
  broker.kill("SIGTERM");
  rmSync(data, { recursive: true, force: true });
}
process.exit(failed ? 1 : 0);
