// SPDX-License-Identifier: GPL-3.0-or-later
// Styles are imported for their side effect (Vite bundles them).
declare module "*.css";
