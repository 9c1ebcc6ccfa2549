// The fixture of the XFeat corridor tests (xfeat_corridor_*_cli_test.cc): `vmap localize` with XFeat on
// corridor_conditions' repeat run (frame i taken where the teach run's frame i was) against a map of its teach run,
// through the built binary, the frames steered by counted as bench/route_conditions.py counts them.
#ifndef VMAP_NEURAL_XFEAT_XFEAT_CORRIDOR_RUN_H_
#define VMAP_NEURAL_XFEAT_XFEAT_CORRIDOR_RUN_H_

#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

namespace vmap::neural {

// The frames of a run carried from repeat frame `from_first`-`from_last` to `to_first`-`to_last`.
std::vector<int> CarriedRun(int from_first, int from_last, int to_first, int to_last);

// corridor_conditions' repeat run against an XFeat map of its teach run, built for each test in a temporary folder.
// Counts frames steered by as (repeat frame, key) pairs.
class XfeatCorridorRun : public ::testing::Test {
 protected:
  using Steered = std::vector<std::pair<int, int>>;

  void SetUp() override;
  // `vmap build`'s flags beyond the matcher's (" --tau 1 --stride 3": a map of places); none: the matcher's map.
  virtual std::string BuildFlags() const { return ""; }
  // The recording the map is built of: the teach run's own folder, or one a test made of it (with times).
  virtual std::filesystem::path Teach() const { return data_ / "teach"; }

  // The key image at or before teach frame `frame`: where a run of the repeat from frame `frame` is started.
  int KeyBefore(int frame) const;

  // The frames steered by when repeat frames `first`-`last` are localized, started at `start_key`, with `flags`.
  Steered SteeredOnRepeat(int first, int last, int start_key, const std::string& flags);

  // The frames steered by when repeat frames taken in the order `repeat_of` gives (a robot carried off: run frame f
  // is repeat frame repeat_of[f]; kBlackFrame: a black frame there) are localized, started at `start_key`, with
  // `flags`.
  static constexpr int kBlackFrame = -1;
  Steered SteeredOnRun(const std::vector<int>& repeat_of, int start_key, const std::string& flags);

  // How many of `steered` (repeat frame, key) are at a key image more than 2 from every right one.
  int Far(const Steered& steered) const;

  // How many of `steered` (repeat frame, key) are at a right key image.
  int Right(const Steered& steered) const;

  // The shape of a test of a rule that keeps frames from being steered by far: with the defaults no frame `steered`
  // gives is more than 2 key images off, with `rule_off` (the rule's flag off, and those of later rules that mend the
  // same frames) at least one is; else the slice no longer reaches the frames it was chosen for, `premise`.
  void ExpectNoFarFrameButWithout(const std::string& rule_off, const std::string& premise,
                                  const std::function<Steered(const std::string&)>& steered);

  const std::filesystem::path data_ = std::filesystem::path(testing::SharedDir()) / "data/corridor_conditions";
  const testing::ScopedTempDir dir_{"corridor"};
  const std::filesystem::path map_ = dir_.path() / "map";
  std::vector<int> sources_;  // the map's key images' teach frames
};

}  // namespace vmap::neural

#endif  // VMAP_NEURAL_XFEAT_XFEAT_CORRIDOR_RUN_H_
