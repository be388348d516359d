// SPDX-License-Identifier: GPL-3.0-or-later
// End-to-end step of the power-fail recovery on the simulated broach (configs/broach-zc.toml):
// the job cuts, the mains fail (the admin's documented simulation control, as a test bench cuts
// the power), the recovery dialog shows the record, the power returns, and with the mouse alone:
// reset, machine on, a 2 mm retract confirmed in the dialog, which then closes.
import { spawn } from "node:child_process";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { serverUrl, stopServer, waitFor as waitForOn } from "./wait.mjs";

const operator = "e2e-operator-token-0123456789", admin = "e2e-admin-token-0123456789";

function serve(opencnc, repo, data) {
  return spawn(opencnc, ["serve", "--machine", join(repo, "configs/broach-zc.toml"), "--listen", "127.0.0.1:0",
    "--program", join(repo, "examples/broach-constant.ngc"), "--data", data, "--static", join(repo, "web/dist"), "--speed", "30"], {
    env: { ...process.env, OPENCNC_OPERATOR_TOKEN: operator, OPENCNC_ADMIN_TOKEN: admin },
    stdio: ["ignore", "pipe", "inherit"],
  });
}

/** Runs the step in a new page of `browser`; throws on a failure (after a screenshot). */
export async function recoveryStep({ opencnc, repo, out, browser, step }) {
  const data = mkdtempSync(join(tmpdir(), "opencnc-e2e-broach-"));
  const server = serve(opencnc, repo, data);
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  let stop = null;
  try {
    const url = await serverUrl(server, "opencnc serve (broach)");
    const base = new URL(url).origin;
    const simulate = async (event) => {
      const r = await fetch(`${base}/api/v1/commands`, { method: "POST", headers: { Authorization: `Bearer ${admin}` },
        body: JSON.stringify({ kind: "simulate", event }) });
      if (r.status !== 200) throw new Error(`simulate ${event}: ${r.status} ${await r.text()}`);
    };
    const dialog = page.getByTestId("dialog");
    const waitFor = (what, check, ms) => waitForOn(page, what, check, ms);
    const dialogSays = async (t) => (await dialog.isVisible()) && (await dialog.innerText()).includes(t);
    await page.goto(url);
    await waitFor("the broach's load panel", async () => (await page.getByTestId("panel-load").innerText()).includes("hold 4 kN"));
    step("broach: cycle start, the cut pulls");
    await page.getByTestId("key-file").click();
    await page.getByTestId("cycle-start").click();
    await waitFor("the load of the cut", async () => {
      const m = /Load (-?[\d.]+) kN/.exec(await page.getByTestId("panel-load").innerText());
      return m !== null && Number(m[1]) > 1;
    });
    step("broach: the mains fail");
    await simulate("mains-off");
    await waitFor("the power-fail dialog", () => dialogSays("The mains are off"));
    await waitFor("the record at rest", () => dialogSays("Stage: at-rest"));
    await page.screenshot({ path: join(out, "08-power-failure.png") });
    step("broach: the power returns; reset and machine on in the dialog");
    await simulate("mains-on");
    await waitFor("the reset button", () => dialogSays("reset and switch the machine on"));
    await dialog.getByRole("button", { name: "Reset" }).click();
    await waitFor("the machine-on button", async () => await dialog.getByRole("button", { name: "Machine on" }).isVisible());
    await dialog.getByRole("button", { name: "Machine on" }).click();
    await waitFor("the choices", async () => await dialog.getByRole("button", { name: "Retract" }).isVisible());
    const z0 = Number(await page.getByTestId("pos-Z").innerText());
    step("broach: retract 2 mm back, confirmed");
    await page.getByTestId("field-distance_mm").fill("2");
    await page.getByTestId("field-distance_mm").dispatchEvent("change");
    await dialog.getByRole("button", { name: "Retract" }).click();
    await waitFor("the question", () => dialogSays("Retract the cutter (distance 2 mm, direction back, at 100 mm/min)"));
    await page.screenshot({ path: join(out, "09-recovery-confirm.png") });
    await page.getByTestId("confirm").click();
    await waitFor("the dialog to close (the record cleared)", async () => !(await dialog.isVisible()));
    // The record clears when the retract ends; the DRO shows it a stream period or more later
    // (30 Hz, virtual time at 30x on a loaded machine), so wait for the position, then check it.
    let z1 = NaN;
    const movedTwo = async () => {
      z1 = Number(await page.getByTestId("pos-Z").innerText());
      return Math.abs(Math.abs(z1 - z0) - 2) <= 0.01;
    };
    await waitFor("Z 2 mm from where it stood", movedTwo, 10000).catch(() => {
      throw new Error(`Z moved ${z1 - z0} mm, not 2`);
    });
    step(`broach: retracted, Z ${z0} -> ${z1}`);
    await page.screenshot({ path: join(out, "10-retracted.png") });
  } catch (e) {
    await page.screenshot({ path: join(out, "failure-broach.png") }).catch(() => {});
    throw e;
  } finally {
    await page.close();
    stop = await stopServer(server);
    rmSync(data, { recursive: true, force: true });
  }
  if (stop) throw new Error(`broach: ${stop}`);
}
