// SPDX-License-Identifier: GPL-3.0-or-later
// Vite: the front end is built into web/dist, which `opencnc serve` serves (index.html, the
// operator's HMI) and `opencnc fleet` too (fleet.html, the shop's fleet view).
import {resolve} from 'node:path';
import { defineConfig } from "vite";

export default defineConfig({
  base: '/',
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    chunkSizeWarningLimit: 1000,
    rollupOptions: {
      input:
          {hmi: resolve(import.meta.dirname, 'index.html'), fleet: resolve(import.meta.dirname, 'fleet.html')}
    },
  },
  test: {include: ['src/**/*.test.ts']},
} as never);
