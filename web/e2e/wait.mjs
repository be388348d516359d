// SPDX-License-Identifier: GPL-3.0-or-later
// Waiting in the end-to-end tests: poll a check on the page until it holds or the time is up.

/** Resolves once `check()` holds; throws "timed out waiting for <what>" after `ms`. */
export async function waitFor(page, what, check, ms = 30000) {
  const end = Date.now() + ms;
  while (Date.now() < end) {
    if (await check()) return;
    await page.waitForTimeout(50);
  }
  throw new Error(`timed out waiting for ${what}`);
}

/**
 * Stops `opencnc serve` with SIGINT, as Ctrl-C would, and resolves to what went wrong, if anything:
 * a controlled stop exits 0 (under the sanitizers a leak or undefined behaviour at exit does not).
 */
export async function stopServer(server) {
  if (server.exitCode === null && server.signalCode === null) {
    const exited = new Promise((ok) => server.on("exit", ok));
    server.kill("SIGINT");
    await exited;
  }
  if (server.exitCode === 0) return null;
  return `opencnc serve ended with ${server.exitCode ?? server.signalCode}, not 0, after SIGINT`;
}

/** Resolves to the URL `opencnc serve` prints; rejects if it exits first or prints none in 20 s. */
export function serverUrl(server, name = "opencnc serve") {
  return new Promise((ok, fail) => {
    let text = "";
    server.stdout.on("data", (d) => {
      text += d;
      const m = /open\s+(http:\S+)/.exec(text);
      if (m) ok(m[1]);
    });
    server.on("exit", (code) => fail(new Error(`${name} exited with ${code}`)));
    setTimeout(() => fail(new Error(`${name} printed no URL in 20 s`)), 20000);
  });
}
