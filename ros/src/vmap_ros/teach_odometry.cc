#include "vmap_ros/teach_odometry.h"

#include "vmap/core/atomic_output.h"

namespace vmap::ros_node {

void WriteTeachOdometry(const std::filesystem::path& map, const std::vector<OdometrySample>& samples) {
  WriteFileAtomically(map / kTeachOdometryFileName, OdometryCsv(samples));
}

}  // namespace vmap::ros_node
