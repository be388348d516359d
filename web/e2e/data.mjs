// SPDX-License-Identifier: GPL-3.0-or-later
// End-to-end steps of the data screens: on the mill (no EDM) the Conditions screen says it has
// no conditions; on the simulated drill (configs/drill-retrofit.toml, a copy the admin may edit)
// the Compensation screen with the mouse: one pitch point of X changed, applied with the admin's
// token, the answer and the profile file show it, and the plot is drawn again from the new table;
// on the simulated EDM (configs/edm-5axis.toml, a copy) the Conditions screen: one value of E1
// changed and applied, a condition added as a copy and another deleted after the confirmation.
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
  const { server, page, profile, close } = await copyServer({ opencnc, repo, browser }, "drill-retrofit");
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
    stop = await close();
  }
  if (stop) throw new Error(`drill: ${stop}`);
}

/** Starts `opencnc serve` on a copy of configs/<name>.toml (and its tool table) with a page in
 * `browser`; returns the page, the profile's path and a function that stops and cleans up. */
async function copyServer({ opencnc, repo, browser }, name) {
  const data = mkdtempSync(join(tmpdir(), `opencnc-e2e-${name}-`));
  for (const f of [`${name}.toml`, `${name}.tbl`]) copyFileSync(join(repo, "configs", f), join(data, f));
  const profile = join(data, `${name}.toml`);
  const server = spawn(opencnc, ["serve", "--machine", profile, "--listen", "127.0.0.1:0", "--programs", join(repo, "examples"),
    "--data", data, "--static", join(repo, "web/dist"), "--speed", "30"], {
    env: { ...process.env, OPENCNC_OPERATOR_TOKEN: operator, OPENCNC_ADMIN_TOKEN: admin },
    stdio: ["ignore", "pipe", "inherit"],
  });
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  const close = async () => {
    await page.close();
    const stop = await stopServer(server);
    rmSync(data, { recursive: true, force: true });
    return stop;
  };
  return { server, page, profile, close };
}

/** The EDM's Conditions screen (F9), the page opened with the admin's token: E1's jump height changed, E4 added as
 * a copy of E3, E9 deleted after the question; the answer, the file and the table read back. */
export async function conditionsStep({ opencnc, repo, out, browser, step }) {
  const { server, page, profile, close } = await copyServer({ opencnc, repo, browser }, "edm-5axis");
  let stop = null;
  try {
    const url = await serverUrl(server, "opencnc serve (edm)");
    const waitFor = (what, check, ms) => waitForOn(page, what, check, ms);
    const result = () => page.locator("#conditions-result").innerText();
    await page.goto(url.replace(/#token=.*/, `#token=${admin}`));  // the page opened with the admin's token
    step("conditions: the EDM's E1 jump height changed by the admin");
    await page.getByTestId("key-conditions").click();
    const row = (n) => page.locator(`#conditions tr[data-condition="${n}"]`);
    await waitFor("the admin's buttons", async () => (await row(1).getByRole("button", { name: "Edit" }).count()) === 1);
    await row(1).getByRole("button", { name: "Edit" }).click();
    await page.fill('#condition-form input[data-field="jump_height_mm"]', "0.3");
    await page.getByRole("button", { name: "Apply E1 (admin)" }).click();
    await waitFor("the change", async () => (await result()).includes("edm.condition.1.jump_height_mm 0.4 → 0.3"));
    if (!readFileSync(profile, "utf8").includes("jump_height_mm = 0.3\njump_period_s = 0.25      # T_on"))
      throw new Error("the profile file does not hold E1's new jump height in its line");
    await waitFor("E1 read back", async () => (await row(1).innerText()).includes("0.3 / 0.25") &&
      (await page.locator('#condition-form input[data-field="jump_height_mm"]').inputValue()) === "0.3");
    await page.screenshot({ path: join(out, "13-conditions-edit.png"), fullPage: true });
    step("conditions: E4 added as a copy of E3, E9 deleted after the question");
    await page.fill("#new-condition", "4");
    await page.selectOption("#new-condition-from", "3");
    await page.getByRole("button", { name: "Add (admin)" }).click();
    await waitFor("the add", async () => (await result()).includes("edm.condition.4 none → a copy of condition 3"));
    await waitFor("E4 in the table", async () => (await row(4).count()) === 1 && (await row(4).innerText()).includes("square 0.08 mm"));
    await row(9).getByRole("button", { name: "Delete" }).click();
    await waitFor("the question", async () => (await page.locator("#delete-question").innerText()).includes("Delete E9"));
    await page.getByRole("button", { name: "Yes, delete E9" }).click();
    await waitFor("the delete", async () => (await result()).includes("edm.condition.9 defined → deleted"));
    await waitFor("E9 gone", async () => (await row(9).count()) === 0);
    const text = readFileSync(profile, "utf8");
    if (!text.includes("[[edm.condition]]\nnumber = 4\n") || text.includes("number = 9"))
      throw new Error("the profile file does not hold E4 and lack E9");
    await page.screenshot({ path: join(out, "14-conditions-added-deleted.png"), fullPage: true });
  } catch (e) {
    await page.screenshot({ path: join(out, "failure-edm.png") }).catch(() => {});
    throw e;
  } finally {
    stop = await close();
  }
  if (stop) throw new Error(`edm: ${stop}`);
}
