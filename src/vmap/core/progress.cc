#include "vmap/core/progress.h"

#include <unistd.h>

#include <cmath>

#include <fmt/format.h>

namespace vmap {

namespace {

std::string FormatDuration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  if (s >= 3600) return fmt::format("{}h{:02}m", s / 3600, (s % 3600) / 60);
  if (s >= 60) return fmt::format("{}m{:02}s", s / 60, s % 60);
  return fmt::format("{}s", s);
}

}  // namespace

ProgressLine::ProgressLine(std::string label, long total, std::string unit, ProgressOptions options, std::FILE* stream)
    : label_(std::move(label)),
      total_(total),
      unit_(std::move(unit)),
      stream_(stream),
      active_(options.enabled && (options.force || isatty(fileno(stream)))),
      min_interval_s_(options.min_interval_s),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressLine::~ProgressLine() { Finish(); }

std::string ProgressLine::Format(const std::string& label, long done, long total, const std::string& unit,
                                 double elapsed_s) {
  const double rate = elapsed_s > 0 ? done / elapsed_s : 0.0;
  std::string text = fmt::format("{}: {}", label, done);
  if (total > 0)
    text += fmt::format("/{} {} ({:.0f}%)", total, unit, 100.0 * done / total);
  else
    text += " " + unit;
  text += fmt::format(", {:.1f} {}/s", rate, unit);
  if (total > 0 && rate > 0 && done < total) text += ", ETA " + FormatDuration((total - done) / rate);
  return text;
}

void ProgressLine::Update(long done) {
  if (!active_) return;
  const auto now = std::chrono::steady_clock::now();
  const bool last = total_ > 0 && done >= total_;
  if (drawn_ && !last && std::chrono::duration<double>(now - last_draw_).count() < min_interval_s_) return;
  last_draw_ = now;
  drawn_ = true;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  // \r and "erase to end of line" redraw in place.
  std::fprintf(stream_, "\r%s\x1b[K", Format(label_, done, total_, unit_, elapsed).c_str());
  std::fflush(stream_);
}

void ProgressLine::Finish() {
  if (active_ && drawn_) {
    std::fprintf(stream_, "\r\x1b[K");
    std::fflush(stream_);
  }
  drawn_ = false;
  active_ = false;
}

}  // namespace vmap
