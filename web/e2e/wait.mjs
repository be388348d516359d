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
