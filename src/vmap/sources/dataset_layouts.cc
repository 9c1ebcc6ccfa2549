// Readers of the list-based layouts: image folders, TUM RGB-D (rgb.txt), EuRoC (cam0/data.csv) and
// KITTI odometry (image_0/ + times.txt).

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/folder_path.h"
#include "vmap/core/number_text.h"
#include "vmap/sources/internal.h"
#include "vmap/sources/kitti_frame_number.h"

namespace vmap::internal {
namespace fs = std::filesystem;

namespace {

// Every entry named as an image, by its name alone: one that is no regular file (a dangling link, a link loop, a
// FIFO, a folder) is then skipped by the source with a warning and counted, not left out without a word.
std::vector<std::string> ImagesIn(const fs::path& directory) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(directory)) {
    if (IsImageFile(entry.path().string())) names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end(), NaturalLess);
  return names;
}

std::string Trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r\n") - begin + 1);
}

// A list file of a dataset (rgb.txt, data.csv, times.txt, timestamps.txt): read only when it is a regular
// file (a FIFO would block) and at most 256 MB.
std::istringstream ListFile(const fs::path& path, const std::string& what) {
  return std::istringstream(ReadNamedFile(path, uint64_t{256} << 20, what, "give the sequence's own " + what));
}

// An optional list file: absent is no list; there, it is read as ListFile reads one (a FIFO or a device is refused,
// not taken for no list).
std::optional<std::istringstream> OptionalListFile(const fs::path& path, const std::string& what) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(path, ec))) return std::nullopt;
  return ListFile(path, what);
}

void RequireExists(const fs::path& image, const std::string& list, int line) {
  if (!fs::exists(image)) {
    throw InputError("'" + list + "' line " + std::to_string(line) + " names '" + image.string() +
                     "', which does not exist; fix or remove that line");
  }
}

// "timestamps.txt" beside an image folder (or in its parent): "file_name seconds" per line.
// An image folder's timestamps.txt ("NAME SECONDS" a line), in the folder or beside it.
struct TimestampsFile {
  fs::path path;
  std::map<std::string, double> stamps;  // by file name
  int first_bad_line = 0;                // the first line that is no "NAME SECONDS" of a finite time (0: none)
};

TimestampsFile ReadTimestampsFile(const fs::path& directory) {
  TimestampsFile read;
  for (const fs::path& candidate :
       {directory / "timestamps.txt", NormalizedFolderPath(directory).parent_path() / "timestamps.txt"}) {
    std::optional<std::istringstream> file = OptionalListFile(candidate, "timestamps file");
    if (!file) continue;
    read = {candidate, {}, 0};
    std::istream& in = *file;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
      line = Trim(line);
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      std::string name;
      double seconds;
      if (fields >> name >> seconds && std::isfinite(seconds)) {
        read.stamps[fs::path(name).filename().string()] = seconds;
      } else if (read.first_bad_line == 0) {
        read.first_bad_line = number;
      }
    }
    if (!read.stamps.empty()) break;
  }
  return read;
}

}  // namespace

std::vector<ImageEntry> ListImageFolder(const std::string& directory_text) {
  fs::path directory(directory_text);
  if (!fs::is_directory(directory)) {
    throw OptionError("format", "images needs a folder of images, and '" + directory_text + "' is not a folder");
  }
  std::vector<std::string> names = ImagesIn(directory);
  if (names.empty()) {
    // A sequence folder often keeps its frames one level down (images/, rgb/, frames/).
    for (const char* sub : {"images", "rgb", "frames", "image", "imgs"}) {
      if (fs::is_directory(directory / sub) && !ImagesIn(directory / sub).empty()) {
        spdlog::info("reading the images in {}", (directory / sub).string());
        directory /= sub;
        names = ImagesIn(directory);
        break;
      }
    }
  }
  if (names.empty()) {
    // Two common mistakes, named: a map folder given as a run, and the folder a video or a recording lies in.
    if (fs::is_regular_file(directory / "map.json") && fs::is_directory(directory / "keys")) {
      throw InputError("'" + directory_text +
                       "' is a vmap map (map.json, keys/), not a run to read frames from; give the video, image folder "
                       "or recording it was built from (`vmap info` names it), and the map where a command takes one "
                       "(vmap localize MAP QUERY)");
    }
    std::vector<std::string> runs;
    std::error_code ec;
    for (const fs::directory_entry& entry : fs::directory_iterator(directory, ec)) {
      std::string extension = entry.path().extension().string();
      for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (entry.is_regular_file(ec) &&
          (extension == ".mp4" || extension == ".avi" || extension == ".mkv" || extension == ".mov" ||
           extension == ".webm" || extension == ".bag" || extension == ".mcap")) {
        runs.push_back(entry.path().string());
      }
    }
    if (!runs.empty()) {
      std::sort(runs.begin(), runs.end());
      std::string named = "'" + runs.front() + "'";
      if (runs.size() > 1) named += fmt::format(" and {} more", runs.size() - 1);
      throw InputError("'" + directory_text + "' holds no images but a video or recording: give it, e.g. " + named);
    }
    throw InputError("'" + directory_text +
                     "' holds no images (.png, .jpg, .bmp, .tif, ...) and is not a TUM (rgb.txt), EuRoC "
                     "(mav0/cam0/data.csv) or KITTI (image_0/ + times.txt) sequence; point to the folder with the "
                     "frames, or give its format");
  }
  const TimestampsFile timestamps = ReadTimestampsFile(directory);
  const std::map<std::string, double>& stamps = timestamps.stamps;
  const auto unstamped =
      std::find_if(names.begin(), names.end(), [&](const std::string& n) { return !stamps.count(n); });
  const bool use_stamps = !stamps.empty() && unstamped == names.end();
  if (!stamps.empty() && !use_stamps) {
    // Every frame or none: a time for some frames only would make the pace jump where it is missing.
    spdlog::warn("'{}' gives no time to image '{}'{}: the frames get no timestamps; fix the file",
                 timestamps.path.string(), *unstamped,
                 timestamps.first_bad_line > 0
                     ? fmt::format(" (line {} is no 'NAME SECONDS')", timestamps.first_bad_line)
                     : std::string());
  }
  // The times say the order the frames were taken in, where the names sort otherwise (names that are not in the
  // order of capture: "b_1.png" after "a_2.png").
  if (use_stamps) {
    const auto earlier = [&](const std::string& x, const std::string& y) { return stamps.at(x) < stamps.at(y); };
    const auto out_of_order = std::is_sorted_until(names.begin(), names.end(), earlier);
    if (out_of_order != names.end()) {
      spdlog::info(
          "the images of '{}' are taken in the order of their times in '{}': their names sort otherwise "
          "('{}' after '{}')",
          directory.string(), timestamps.path.string(), *out_of_order, *(out_of_order - 1));
      std::stable_sort(names.begin(), names.end(), earlier);
    }
  }
  std::vector<ImageEntry> entries;
  entries.reserve(names.size());
  for (const std::string& name : names) {
    entries.push_back({(directory / name).string(), use_stamps ? stamps.at(name) : -1.0});
  }
  return entries;
}

std::vector<ImageEntry> ListTum(const std::string& rgb_txt) {
  std::istringstream in = ListFile(rgb_txt, "TUM RGB-D image list (rgb.txt)");
  const fs::path base = fs::path(rgb_txt).parent_path();
  std::vector<ImageEntry> entries;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    line = Trim(line);
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double stamp;
    std::string file;
    if (!(fields >> stamp >> file)) {
      throw InputError("'" + rgb_txt + "' line " + std::to_string(number) +
                       " is not 'timestamp filename' (TUM RGB-D format); fix that line");
    }
    RequireExists(base / file, rgb_txt, number);
    entries.push_back({(base / file).string(), stamp});
  }
  if (entries.empty()) throw InputError("'" + rgb_txt + "' lists no images; the sequence is empty");
  return entries;
}

std::vector<ImageEntry> ListEuroc(const std::string& data_csv) {
  std::istringstream in = ListFile(data_csv, "EuRoC image list (mav0/cam0/data.csv)");
  const fs::path images = fs::path(data_csv).parent_path() / "data";
  std::vector<ImageEntry> entries;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    line = Trim(line);
    if (line.empty() || line[0] == '#') continue;
    const auto comma = line.find(',');
    if (comma == std::string::npos) {
      throw InputError("'" + data_csv + "' line " + std::to_string(number) +
                       " is not 'timestamp_ns,filename' (EuRoC format); fix that line");
    }
    // The whole field, in decimal: std::stoll took "12abc" for 12 and seconds ("1403636580.1") for 1403636580 ns.
    const std::string field = Trim(line.substr(0, comma));
    long long nanoseconds = 0;
    const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), nanoseconds);
    if (field.empty() || error != std::errc() || end != field.data() + field.size()) {
      throw InputError("'" + data_csv + "' line " + std::to_string(number) + ": '" + field +
                       "' is no timestamp in integer nanoseconds (EuRoC format); fix that line");
    }
    const std::string file = Trim(line.substr(comma + 1));
    RequireExists(images / file, data_csv, number);
    entries.push_back({(images / file).string(), nanoseconds * 1e-9});
  }
  if (entries.empty()) throw InputError("'" + data_csv + "' lists no images; the sequence is empty");
  return entries;
}

std::vector<ImageEntry> ListKitti(const std::string& sequence_directory) {
  const fs::path sequence(sequence_directory);
  fs::path images = sequence / "image_0";
  if (!fs::is_directory(images)) images = sequence / "image_2";
  if (!fs::is_directory(images)) {
    throw InputError("'" + sequence_directory + "' is not a KITTI odometry sequence: it has no image_0/ folder");
  }
  const std::vector<std::string> names = ImagesIn(images);
  if (names.empty()) throw InputError("'" + images.string() + "' holds no images; the sequence is empty");
  std::vector<double> times;
  if (std::optional<std::istringstream> in = OptionalListFile(sequence / "times.txt", "KITTI times.txt")) {
    std::string line;
    for (int number = 1; std::getline(*in, line); ++number) {
      line = Trim(line);
      if (line.empty()) continue;
      const std::optional<double> t = ParseNumber(line);
      if (!t || !std::isfinite(*t) || *t < 0.0) {
        spdlog::warn("{} line {}: {:?} is not a time in seconds; ignoring the timestamps",
                     (sequence / "times.txt").string(), number, line.substr(0, 40));
        times.clear();
        break;
      }
      times.push_back(*t);
    }
  }
  // An image takes the time of its frame number (000123.png: line 123), so a sequence with images missing
  // keeps every time right; by position only when the names are no numbers within times.txt.
  std::vector<size_t> time_lines(names.size());
  bool numbered = !times.empty();
  for (size_t i = 0; i < names.size() && numbered; ++i) {
    const std::optional<int> number = KittiFrameNumber(names[i]);
    numbered = number && static_cast<size_t>(*number) < times.size();
    if (numbered) time_lines[i] = static_cast<size_t>(*number);
  }
  if (numbered && names.size() != times.size()) {
    spdlog::info("{} holds {} of the {} images {} times; each takes the time of its number", images.string(),
                 names.size(), times.size(), (sequence / "times.txt").string());
  } else if (!numbered && !times.empty()) {
    if (times.size() != names.size()) {
      spdlog::warn("{} has {} times for {} images; ignoring the timestamps", (sequence / "times.txt").string(),
                   times.size(), names.size());
      times.clear();
    }
    for (size_t i = 0; i < names.size(); ++i) time_lines[i] = i;
  }
  std::vector<ImageEntry> entries;
  for (size_t i = 0; i < names.size(); ++i) {
    entries.push_back({(images / names[i]).string(), times.empty() ? -1.0 : times[time_lines[i]]});
  }
  return entries;
}

}  // namespace vmap::internal
