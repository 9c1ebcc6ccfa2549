#include "vmap_ros/teach_odometry.h"

#include "vmap/core/atomic_output.h"

namespace vmap::ros_node {

void WriteTeachOdometry(const std::filesystem::path& map, const std::vector<OdometrySample>& samples) {
  WriteFileAtomically(map / kTeachOdometryFileName, OdometryCsv(samples));
}

std::vector<OdometrySample> TeachOdometryFor(const std::filesystem::path& map, const std::string& given,
                                             const std::string& topic) {
  if (!given.empty()) return ReadOdometry(given, topic);
  std::error_code error;
  const std::filesystem::path beside = map / kTeachOdometryFileName;
  if (std::filesystem::is_regular_file(beside, error)) return ReadOdometryCsv(beside);
  return {};
}

}  // namespace vmap::ros_node
