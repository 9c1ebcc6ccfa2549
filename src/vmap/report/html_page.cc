#include "vmap/report/html_page.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/image_file.h"
#include "vmap/report/html_util.h"
#include "vmap/report/report_assets.h"

namespace vmap::report {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Any request to the network (or to anything but files next to the page) is refused by the browser.
constexpr const char* kContentSecurityPolicy =
    "default-src 'none'; img-src 'self' data:; media-src 'self'; style-src 'unsafe-inline'; "
    "script-src 'unsafe-inline'";

}  // namespace

std::string PageStart(const std::string& title, const std::string& heading, const std::string& subtitle,
                      const std::vector<std::pair<std::string, std::string>>& nav) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       << "<meta http-equiv=\"Content-Security-Policy\" content=\"" << kContentSecurityPolicy << "\">\n"
       << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
       << "<meta name=\"generator\" content=\"vmap " << VMAP_VERSION << "\">\n"
       << "<title>" << HtmlEscape(title) << "</title>\n<style>\n"
       << ReportCss() << "</style>\n</head>\n<body>\n"
       << "<header><h1>" << HtmlEscape(heading) << "</h1><p>" << HtmlEscape(subtitle) << "</p></header>\n<nav>";
  for (const auto& [anchor, text] : nav) html << "<a href=\"#" << anchor << "\">" << HtmlEscape(text) << "</a>";
  html << "</nav>\n<main>\n";
  return html.str();
}

std::string PageEnd() {
  return std::string("</main>\n<footer>Written by vmap ") + VMAP_VERSION +
         ". This page works offline: everything it shows is in this file and the folder next to it.</footer>\n"
         "<script>\n" +
         std::string(ReportJs()) + "</script>\n</body>\n</html>\n";
}

namespace {

// The first value named `name` anywhere in the options (they may be grouped per stage).
const json* FindOption(const json& node, const std::string& name) {
  if (node.is_object()) {
    auto it = node.find(name);
    if (it != node.end()) return &*it;
    for (const auto& [key, value] : node.items()) {
      if (const json* found = FindOption(value, name)) return found;
    }
  }
  return nullptr;
}

}  // namespace

json ParseOptions(const std::string& text) {
  try {
    json options = json::parse(text.empty() ? "{}" : text);
    return options.is_object() ? options : json::object();
  } catch (const json::exception&) {
    return json::object();
  }
}

// An option as one line: a grouped option (matcher, verifier) reads "orb (features 2000, ...)".
std::string OptionText(const json& options, const std::string& name) {
  const json* value = FindOption(options, name);
  if (!value || value->is_null()) return "not recorded";
  if (value->is_string()) return value->get<std::string>();
  if (!value->is_object()) return value->dump();
  std::string headline;
  for (const char* key : {"name", "method", "type", "matcher"}) {
    auto it = value->find(key);
    if (it != value->end() && it->is_string()) {
      headline = it->get<std::string>();
      break;
    }
  }
  std::string details;
  for (const auto& [key, item] : value->items()) {
    if (item.is_structured() || (item.is_string() && item.get<std::string>() == headline)) continue;
    details += (details.empty() ? "" : ", ") + key + " " + (item.is_string() ? item.get<std::string>() : item.dump());
  }
  if (headline.empty()) return details.empty() ? value->dump() : details;
  return details.empty() ? headline : headline + " (" + details + ")";
}

std::string TimestampText(double seconds) { return seconds < 0 ? "" : FormatFixed(seconds, 2) + " s"; }

std::string SizeText(const cv::Size& size) {
  return size.area() > 0 ? std::to_string(size.width) + " x " + std::to_string(size.height) : "unknown";
}

std::string DurationText(double seconds) {
  if (seconds < 60) return FormatFixed(seconds, 1) + " s";
  const int minutes = static_cast<int>(seconds / 60);
  return std::to_string(minutes) + " min " + FormatFixed(seconds - 60.0 * minutes, 0) + " s";
}

std::string Card(const std::string& value, const std::string& label) {
  return "<div class=\"card\"><div class=\"value\">" + HtmlEscape(value) + "</div><div class=\"label\">" +
         HtmlEscape(label) + "</div></div>";
}

std::string OptionsSection(const nlohmann::json& options, const std::string& summary) {
  return "<section id=\"options\"><h2>Options</h2>\n<details><summary>" + summary + "</summary><pre>" +
         HtmlEscape(options.dump(2)) + "</pre></details>\n</section>\n";
}

std::string Row(const std::string& name, const std::string& value_html) {
  return "<tr><th>" + HtmlEscape(name) + "</th><td>" + value_html + "</td></tr>\n";
}

// A file name or path as the page shows it: the page is UTF-8, so a name that is not is shown percent-encoded,
// as map.json stores it.
std::string Displayable(const std::string& name) { return IsValidUtf8(name) ? name : EncodeFileName(name); }

std::string Numbered(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.jpg", index);
  return name;
}

void WriteJpeg(const fs::path& file, const cv::Mat& image, int quality) {
  WriteImageFile(file, image, "the report's image", {cv::IMWRITE_JPEG_QUALITY, quality});
}

cv::Mat ScaledToWidth(const cv::Mat& image, int width) {
  if (width <= 0 || image.cols <= width) return image;
  cv::Mat scaled;
  const int height = std::max(1, static_cast<int>(std::lround(static_cast<double>(image.rows) * width / image.cols)));
  cv::resize(image, scaled, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return scaled;
}

}  // namespace vmap::report
