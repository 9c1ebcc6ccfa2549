#include "vmap/localization/localization_result.h"

#include <cmath>

namespace vmap {

std::string LocalizationStatusName(LocalizationStatus status) { return EnumToName(kLocalizationStatusNames, status); }

std::string WithholdingName(Withholding rule) { return EnumToName(kWithholdingNames, rule); }

std::string LocalizationGuidance(const LocalizationResult& result) {
  if (result.status == LocalizationStatus::kLost) return "none: lost";
  if (result.status == LocalizationStatus::kUncertain) {
    if (result.withheld_by == Withholding::kNone) return "none: position uncertain";
    return "none: position uncertain (" + WithholdingName(result.withheld_by) + ")";
  }
  if (!std::isfinite(result.heading_px)) return "none";
  const KeyComparison& target = result.next_key >= 0 ? result.to_next : result.to_key;
  if (!target.pose.valid) return "heading only: no pose";
  return result.translation_known ? "heading and translation" : "heading only: translation unknown";
}

bool MaySteerBy(const LocalizationResult& result) {
  return IsPlaced(result.status) && std::isfinite(result.heading_px);
}

}  // namespace vmap
