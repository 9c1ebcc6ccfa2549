#pragma once
// The frame of vmap's HTML pages (head with the offline Content-Security-Policy, style, navigation, footer
// and script) and the small pieces the map report and the localization report share.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace vmap::report {

// The page up to the opening of <main>; `nav` lists (anchor, text) pairs.
std::string PageStart(const std::string& title, const std::string& heading, const std::string& subtitle,
                      const std::vector<std::pair<std::string, std::string>>& nav);
// Closes <main> and the page (footer and script).
std::string PageEnd();

// Options text as a JSON object ({} when it is not one).
nlohmann::json ParseOptions(const std::string& text);
// An option as one line, for display whatever this vmap knows of it (decisions read options typed:
// mapping/map_builder.h, RecordedOptions): a grouped option (matcher, verifier) reads "orb (features 2000, ...)".
std::string OptionText(const nlohmann::json& options, const std::string& name);

std::string TimestampText(double seconds);  // "" for a negative (unknown) time
std::string SizeText(const cv::Size& size);
std::string DurationText(double seconds);

// A summary card (a big value over a small label) and a row of a summary table (the value is HTML).
std::string Card(const std::string& value, const std::string& label);
std::string Row(const std::string& name, const std::string& value_html);
// The folded section that lists every option of the run (`summary`: the fold's title, HTML).
std::string OptionsSection(const nlohmann::json& options, const std::string& summary);

// A file name or path as a page shows it: the page is UTF-8, so a name that is not is shown percent-encoded,
// as map.json stores it.
std::string Displayable(const std::string& name);

std::string Numbered(int index);  // "000012.jpg"
// Throws InputError naming the file when it cannot be written.
void WriteJpeg(const std::filesystem::path& file, const cv::Mat& image, int quality);
cv::Mat ScaledToWidth(const cv::Mat& image, int width);  // never enlarges

}  // namespace vmap::report
