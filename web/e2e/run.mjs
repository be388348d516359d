// SPDX-License-Identifier: GPL-3.0-or-later
// End-to-end test of the HMI in headless Chromium (Debian's, driven by playwright-core): starts
// `opencnc serve` on the simulated mill (virtual time at 30x), then with the mouse alone: machine
// on, home, open the bracket program, run it, confirm the tool changes, hold and resume, see the
// position change, run to the end, find the job in the history; then run it again from line 66
// chosen in the listing; as the admin, lower X's maximum velocity and see a bad value refused with
// the profile's message (the profile is a copy in the test's folder); the Conditions screen
// saying the mill has none, one pitch point changed on the drill's Compensation screen, and on the
// EDM a condition's value changed, a condition added and one deleted (data.mjs); then the power-fail recovery on the broach (recovery.mjs). Screenshots land in the
// artefacts folder. Usage: node e2e/run.mjs [--opencnc PATH] [--out DIR]
import { spawn } from "node:child_process";
import { copyFileSync, mkdtempSync, readFileSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { chromium } from "playwright-core";
import { compensationStep, conditionsStep, noConditionsStep } from "./data.mjs";
import { recoveryStep } from "./recovery.mjs";
import { commandLine } from "./cli.mjs";
import { serverUrl, stopServer, waitFor as waitForOn } from "./wait.mjs";

const { repo, opencnc, out } = commandLine("e2e/run.mjs");
const data = mkdtempSync(join(tmpdir(), "opencnc-e2e-"));
// The profile is a copy: the admin's step changes a machine parameter, which writes the file.
for (const f of ["mill-3axis.toml", "mill-3axis.tbl"]) copyFileSync(join(repo, "configs", f), join(data, f));

const server = spawn(opencnc, ["serve", "--machine", join(data, "mill-3axis.toml"), "--listen", "127.0.0.1:0",
  "--programs", join(repo, "examples"), "--data", data, "--static", join(repo, "web/dist"), "--speed", "30"], {
  env: { ...process.env, OPENCNC_OPERATOR_TOKEN: "e2e-operator-token-0123456789", OPENCNC_ADMIN_TOKEN: "e2e-admin-token-0123456789" },
  stdio: ["ignore", "pipe", "inherit"],
});
const url = await serverUrl(server);

const browser = await chromium.launch({
  executablePath: "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
});
let failed = false;
const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
page.on("pageerror", (e) => console.error(`page error: ${e.message}`));
const step = (what) => console.log(`e2e: ${what}`);
const shot = (name) => page.screenshot({ path: join(out, `${name}.png`) });
const text = (id) => page.getByTestId(id).innerText();
const waitFor = (what, check, ms) => waitForOn(page, what, check, ms);
// The dialog's button with this label, clicked when it is there. The dialog may close between the
// look and the click (the stream redraws it): a click that finds no button is let go, and the
// caller's wait for what the answer does tells whether it took.
const answer = async (label) => {
  const b = page.getByTestId("dialog").getByRole("button", { name: label });
  if (await b.isVisible()) await b.click({ timeout: 2000 }).catch(() => {});
};

try {
  await page.goto(url);
  await waitFor("the status", async () => (await text("state")).length > 0);
  step("machine on");
  await page.click("#machine-on");
  await waitFor("idle", async () => (await text("state")).startsWith("idle"));
  step("home all");
  await page.getByTestId("key-jog").click();
  await page.getByTestId("home-all").click();
  await waitFor("homed", async () => (await page.locator("table.dro td").allInnerTexts()).filter((t) => t === "●").length === 3);
  await shot("01-homed");
  step("open the bracket program");
  await page.getByTestId("key-file").click();
  await page.getByTestId("programs").selectOption("bracket.ngc");
  await page.getByTestId("open").click();
  await waitFor("the program", async () => (await page.locator(".progname").innerText()).startsWith("bracket.ngc"));
  await page.waitForTimeout(500);  // the preview
  await shot("02-opened");
  const x0 = await text("pos-X");
  step("cycle start");
  await page.getByTestId("cycle-start").click();
  await waitFor("the tool change dialog", async () => (await page.getByTestId("dialog").innerText()).includes("Tool change"));
  await shot("03-tool-change");
  await answer("Tool is in — continue");
  await waitFor("motion", async () => (await text("pos-X")) !== x0);
  step(`the position changed: X ${x0} -> ${await text("pos-X")}`);
  await waitFor("a fifth of the program", async () => Number(await page.locator("progress").getAttribute("value")) > 0.2);
  step("feed hold");
  await page.getByTestId("feed-hold").click();
  await waitFor("held", async () => (await text("state")).startsWith("held"));
  // "held" shows at once while the axes still decelerate along the path (longer on a busy
  // machine): wait until X has rested for half a second, then it must stay there. The DRO shows
  // the encoders, not the command: "rested" is within 2 µm, not the same text to the last digit
  // (a clean-clone run once timed out waiting for the text to hold still).
  const xNow = async () => Number(await text("pos-X"));
  let last = await xNow();
  let since = Date.now();
  await waitFor("the axes at rest", async () => {
    const now = await xNow();
    if (Math.abs(now - last) > 0.002) [last, since] = [now, Date.now()];
    return Date.now() - since >= 500;
  });
  const held = await xNow();
  await page.waitForTimeout(500);
  if (Math.abs((await xNow()) - held) > 0.002) throw new Error("the machine moved while held");
  await shot("04-held");
  step("resume");
  await answer("Resume");
  await waitFor("running again", async () => (await text("state")).startsWith("running"));
  step("to the end (confirming the second tool)");
  await waitFor("the end of the program", async () => {
    await answer("Tool is in — continue");
    return (await page.getByTestId("messages").innerText()).includes("finished");
  }, 120000);
  await shot("05-finished");
  step("the history");
  await page.getByTestId("key-history").click();
  await waitFor("the history entry", async () => {
    const rows = await page.getByTestId("history").innerText();
    return rows.includes("bracket.ngc") && rows.includes("finished");
  });
  await shot("06-history");
  step("run from line 66 (the drilling), chosen in the listing");
  if (!(await page.locator("table.dro thead").innerText()).includes("work G54")) throw new Error("the DRO names no G54");
  await page.getByTestId("key-file").click();
  await page.locator("ol.listing li").nth(65).click();
  if ((await page.getByTestId("from-line").inputValue()) !== "66") throw new Error("the listing did not choose line 66");
  const finished = async () => ((await page.getByTestId("messages").innerText()).match(/finished/g) ?? []).length;
  const before = await finished();
  await page.getByTestId("run-from-line").click();
  await waitFor("the approach and the drilling", async () => {
    await answer("Tool is in — continue");
    return (await finished()) >= before + 2;  // the approach, then the program
  }, 60000);
  await shot("07-run-from-line");
  step("machine parameters: the admin lowers X's maximum velocity, then a bad value is refused");
  await page.getByTestId("key-params").click();
  await page.fill("#admin-token", "e2e-admin-token-0123456789");
  const vx = page.locator('input[data-key="axis.x.max_velocity"]');
  await waitFor("the parameters", async () => (await vx.count()) === 1);
  await vx.fill("90");
  await page.getByRole("button", { name: "Apply changes (admin)" }).click();
  await waitFor("the change", async () => (await page.locator("#parameters-result").innerText()).includes("axis.x.max_velocity 100.0 → 90.0"));
  if (!readFileSync(join(data, "mill-3axis.toml"), "utf8").includes("max_velocity = 90.0")) throw new Error("the profile file was not changed");
  await vx.fill("-5");
  await page.getByRole("button", { name: "Apply changes (admin)" }).click();
  await waitFor("the profile's message", async () => (await page.locator("#parameters-result").innerText()).includes("the profile refuses the change: "));
  await shot("08-parameters");
  await noConditionsStep({ page, out, step });
  await compensationStep({ opencnc, repo, out, browser, step });
  await conditionsStep({ opencnc, repo, out, browser, step });
  await recoveryStep({ opencnc, repo, out, browser, step });
  step("passed");
} catch (e) {
  failed = true;
  console.error(`e2e: FAILED: ${e.message}`);
  await shot("failure").catch(() => {});
} finally {
  await browser.close();
  const stop = await stopServer(server);
  if (stop) {
    failed = true;
    console.error(`e2e: FAILED: ${stop}`);
  }
  rmSync(data, { recursive: true, force: true });
}
console.log(`e2e: screenshots in ${out}`);
process.exit(failed ? 1 : 0);
