#include "vmap/mapping/sweep_thresholds.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "vmap/core/error.h"
#include "vmap/core/number_text.h"
#include "vmap/mapping/key_image_selector.h"

namespace vmap {

std::vector<double> ParseThresholds(const std::string& text) {
  std::vector<double> taus;
  // start:stop:step, three numbers.
  std::vector<std::optional<double>> range;
  std::stringstream parts(text);
  for (std::string part; std::getline(parts, part, ':');) range.push_back(ParseNumber(part));
  if (range.size() == 3 && range[0] && range[1] && range[2] && text.back() != ':') {
    const double start = *range[0], stop = *range[1], step = *range[2];
    if (!std::isfinite(start) || !std::isfinite(stop) || !(step > 0) || !std::isfinite(step) || stop < start) {
      throw OptionError("thresholds", "'" + text + "' must be start:stop:step with step > 0 and stop >= start");
    }
    // Count steps with a tolerance so that 0.1:0.9:0.1 includes 0.9; counted in double before anything is
    // allocated, so that a tiny step is refused rather than filling the memory.
    const double count = std::floor((stop - start) / step + 1e-9) + 1;
    if (count > kMaxThresholds) {
      throw OptionError("thresholds", fmt::format("'{}' gives {:.7g} thresholds, more than {}; use a larger step", text,
                                                  count, kMaxThresholds));
    }
    // 12 significant digits drop the sum's noise (0.1 + 2 * 0.1 is 0.30000000000000004) and keep a tiny tau tiny,
    // which a fixed number of decimals would round to 0.
    for (int i = 0; i < static_cast<int>(count); ++i) {
      const std::string rounded = fmt::format("{:.12g}", start + i * step);
      taus.push_back(*ParseNumber(rounded));  // fmt writes no locale's decimal comma
    }
  } else {
    std::stringstream list(text);
    std::string item;
    while (std::getline(list, item, ',')) {
      const std::optional<double> tau = ParseNumber(item);
      if (!tau) {
        throw OptionError("thresholds", "'" + text + "' is not start:stop:step (0.1:0.9:0.1) or a list (0.2,0.5)");
      }
      taus.push_back(*tau);
      if (taus.size() > kMaxThresholds) {
        throw OptionError("thresholds",
                          "'" + text + "' lists more than " + std::to_string(kMaxThresholds) + " thresholds");
      }
    }
  }
  if (taus.empty()) throw OptionError("thresholds", "'" + text + "' gives no threshold");
  for (size_t i = 0; i < taus.size(); ++i) {
    KeyImageOptions check;
    check.tau = taus[i];
    check.Check();
    for (size_t j = 0; j < i; ++j) {
      if (taus[j] == taus[i]) throw OptionError("thresholds", fmt::format("'{}' gives tau = {} twice", text, taus[i]));
    }
  }
  return taus;
}

}  // namespace vmap
