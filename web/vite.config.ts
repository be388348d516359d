// SPDX-License-Identifier: GPL-3.0-or-later
// Vite: the front end is built into web/dist, which `opencnc serve` serves.
import { defineConfig } from "vite";

export default defineConfig({
  base: "/",
  build: { outDir: "dist", emptyOutDir: true, chunkSizeWarningLimit: 1000 },
  test: { include: ["src/**/*.test.ts"] },
} as never);
