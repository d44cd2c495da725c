// The page is served by motiondb-server from web/dist: relative asset URLs, everything bundled
// (no network at run time), one small vendor chunk for three.js so that app changes stay cheap
// for the browser cache.
import { defineConfig } from "vite";

export default defineConfig({
  base: "./",
  build: {
    outDir: "dist",
    emptyOutDir: true,
    target: "es2020",
    chunkSizeWarningLimit: 800,
    rollupOptions: {
      output: { manualChunks: { three: ["three"] } },
    },
  },
  server: {
    // `npm run dev` against a server on the default HTTP port.
    proxy: { "/v1": "http://127.0.0.1:8080" },
  },
});
