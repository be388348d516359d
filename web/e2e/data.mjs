// SPDX-License-Identifier: GPL-3.0-or-later
// End-to-end steps of the data screens: on the mill (no EDM) the Conditions screen says it has
// no conditions; on the simulated drill (configs/drill-retrofit.toml, a copy the admin may edit)
// the Compensation screen with the mouse: one pitch point of X changed, applied with the admin's
// token, the answer and the profile file show it, and the plot is drawn again from the new table.
import { spawn } from "node:child_process";
import { copyFileSync, mkdtempSync, readFileSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { serverUrl, stopServer, waitFor as waitForOn } from "./wait.mjs";

const operator = "e2e-operator-token-0123456789", admin = "e2e-admin-token-0123456789";

/** The Conditions screen (F9) of `page`'s machine, which has none (the mill): it says so. */
export async function noConditionsStep({ page, out, step }) {
  step("conditions: the mill has none and the screen says so");
  await page.getByTestId("key-conditions").click();
  await waitForOn(page, "the conditions' note", async () =>
    (await page.locator('[data-screen-root="conditions"]').innerText()).includes("This machine has no machining conditions"));
  await page.screenshot({ path: join(out, "11-no-conditions.png") });
}

/** Runs the drill's compensation step in a new page of `browser`; throws on a failure (after a screenshot). */
export async function compensationStep({ opencnc, repo, out, browser, step }) {
  const data = mkdtempSync(join(tmpdir(), "opencnc-e2e-drill-"));
  for (const f of ["drill-retrofit.toml", "drill-retrofit.tbl"]) copyFileSync(join(repo, "configs", f), join(data, f));
  const profile = join(data, "drill-retrofit.toml");
  const server = spawn(opencnc, ["serve", "--machine", profile, "--listen", "127.0.0.1:0", "--programs", join(repo, "examples"),
    "--data", data, "--static", join(repo, "web/dist"), "--speed", "30"], {
    env: { ...process.env, OPENCNC_OPERATOR_TOKEN: operator, OPENCNC_ADMIN_TOKEN: admin },
    stdio: ["ignore", "pipe", "inherit"],
  });
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  let stop = null;
  try {
    const url = await serverUrl(server, "opencnc serve (drill)");
    const waitFor = (what, check, ms) => waitForOn(page, what, check, ms);
    await page.goto(url);
    step("compensation: the drill's X table, one point changed by the admin");
    await page.getByTestId("key-compensation").click();
    const x = page.locator("#comp-X");
    const point = x.locator('input[data-point="3"][data-dir="forward"]');
    await waitFor("X's table", async () => (await point.count()) === 1);
    const plot = x.locator(".plot polyline.forward");
    const before = await plot.getAttribute("points");
    await page.fill("#comp-admin-token", admin);
    await point.fill("0.012");
    await x.getByRole("button", { name: "Apply table (admin)" }).click();
    // The answer goes to the message line (the section is drawn again from the new table).
    await waitFor("the change", async () =>
      (await page.getByTestId("messages").innerText()).includes("axis.x.compensation.forward 13 points → 13 points, 1 changed (largest 0.01 → 0.012 at 150.0)"));
    const text = readFileSync(profile, "utf8");
    if (!/forward = \[0\.0, 0\.003, 0\.006, 0\.012,/.test(text)) throw new Error("the profile file does not hold the new point");
    // The screen loads the table again after the change: the new section's input and plot.
    await waitFor("the table read back", async () => (await x.locator('input[data-point="3"][data-dir="forward"]').inputValue()) === "0.012");
    const after = await x.locator(".plot polyline.forward").getAttribute("points");
    if (!before || !after || before === after) throw new Error("the plot was not drawn again with the new point");
    await page.screenshot({ path: join(out, "12-compensation.png"), fullPage: true });
  } catch (e) {
    await page.screenshot({ path: join(out, "failure-drill.png") }).catch(() => {});
    throw e;
  } finally {
    await page.close();
    stop = await stopServer(server);
    rmSync(data, { recursive: true, force: true });
  }
  if (stop) throw new Error(`drill: ${stop}`);
}
