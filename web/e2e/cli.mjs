// SPDX-License-Identifier: GPL-3.0-or-later
// The end-to-end scripts' command line: [--opencnc PATH] [--out DIR]; --help prints the usage,
// anything else exits 2.
import { mkdirSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));

/** The repository, the opencnc to test and the artefacts folder (made) of `script` ("e2e/run.mjs"). */
export function commandLine(script) {
  const repo = resolve(here, "..", "..");
  const args = process.argv.slice(2);
  if (args.includes("--help") || args.includes("-h")) {
    console.log(`usage: node ${script} [--opencnc build/opencnc] [--out web/e2e/artifacts]`);
    process.exit(0);
  }
  for (let i = 0; i < args.length; i += 2) {
    if (!["--opencnc", "--out"].includes(args[i]) || i + 1 >= args.length) {
      console.error(`${script}: unknown option or no value: '${args[i]}'`);
      process.exit(2);
    }
  }
  const opt = (name, fallback) => {
    const i = args.indexOf(name);
    return i >= 0 ? args[i + 1] : fallback;
  };
  const out = resolve(opt("--out", join(here, "artifacts")));
  mkdirSync(out, { recursive: true });
  return { repo, opencnc: resolve(opt("--opencnc", join(repo, "build", "opencnc"))), out };
}
