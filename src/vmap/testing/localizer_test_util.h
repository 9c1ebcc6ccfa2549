#pragma once
// Test helpers of the Localizer's tests (localization/localizer*_test.cc): the maps of the sideways drive they
// localize against (built once a process), its frames localized against them, and the comparisons a test gives a
// frame instead of its own (Localizer::Localize's `ahead`).

#include <vector>

#include <opencv2/core.hpp>

#include "vmap/localization/localization_map.h"
#include "vmap/localization/localizer.h"

namespace vmap::testing {

// The map of the drive's even frames (ORB, the default tau): a few key images.
const LocalizationMap& EvenDriveMap();
// The map of the drive's even frames at a high tau (ORB, tau 0.8): many key images, each sharing much with its
// neighbours.
const LocalizationMap& DenseDriveMap();

// `image` (BGR) as the `index`-th frame of a stream, the source's frame `source_index`.
Frame MakeFrame(const cv::Mat& image, int index, int source_index);

// `image` localized by `localizer` (of EvenDriveMap()) as the `index`-th frame of a stream, the source's frame
// `source_index`.
LocalizationResult LocalizeOnEvenMap(Localizer& localizer, const cv::Mat& image, int index, int source_index);

// Drive frame `source_index` localized by `localizer` (of DenseDriveMap()) as the `index`-th frame of a stream;
// `given`: comparisons the frame is taken to have made already (Localizer::Localize's `ahead`).
LocalizationResult LocalizeOnDenseMap(Localizer& localizer, int source_index, int index,
                                      std::vector<KeyComparison> given = {});

// Drive frames `source_indices` localized by `localizer` (of DenseDriveMap()) one after the other as the next frames
// of a stream, `*index` counting them; the last frame's result.
LocalizationResult LocalizeFramesOnDenseMap(Localizer& localizer, const std::vector<int>& source_indices, int* index);

// Whether `key` is one of the key images of `map` around the source's frame `source_index` (KeysAround).
bool Brackets(const VisualMap& map, int source_index, int key);

// A comparison with key image `key` that verified `verified` matches at `log10_nfa` when `seen`, nothing otherwise.
KeyComparison GivenComparison(int key, bool seen, int verified, double log10_nfa);

}  // namespace vmap::testing
