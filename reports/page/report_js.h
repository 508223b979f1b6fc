// The three libraries the report's plots run on (reports/page/vega_plot.h), minified, as the build
// inlined them into armfault from reports/web/node_modules (versions pinned with their
// integrity hashes in reports/web/package-lock.json; reports/CMakeLists.txt and
// reports/page/embed_js.cmake), so that report.html carries them and works offline.
#pragma once

namespace armfault::report_js {

const char* Vega();       // vega/build/vega.min.js
const char* VegaLite();   // vega-lite/build/vega-lite.min.js
const char* VegaEmbed();  // vega-embed/build/vega-embed.min.js
// "vega 6.4.0, vega-lite 6.5.0, vega-embed 7.3.0": what Vega(), VegaLite(), VegaEmbed() are.
const char* Versions();

}  // namespace armfault::report_js
