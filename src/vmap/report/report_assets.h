#pragma once
// The report pages' style sheet and script, embedded into the library at build time from assets/report.css
// and assets/report.js (see embed_assets.cmake): the pages carry them inline and no file is looked up at run
// time. Shared by the map, sweep and localization reports (html_page.h).
//
// report.js plays the key images in order (the route preview) and, when a page is opened as
// report.html#selfcheck, loads every image and records what it found in a <pre id="vmap-selfcheck"> for
// automated checks (report_browser_test.cc).

#include <string_view>

namespace vmap::report {

std::string_view ReportCss();
std::string_view ReportJs();

}  // namespace vmap::report
