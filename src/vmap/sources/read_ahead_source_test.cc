#include "vmap/sources/read_ahead_source.h"

#include <gtest/gtest.h>

#include "vmap/core/error.h"

namespace vmap {
namespace {

// Counts frames up to `frames`, then throws when `fail` (a source whose input breaks), else ends.
class CountingSource : public FrameSource {
 public:
  CountingSource(int frames, bool fail) : frames_(frames), fail_(fail) { info_.expected_frames = frames; }
  std::optional<Frame> Next() override {
    if (next_ == frames_) {
      if (fail_) throw InputError("frame " + std::to_string(next_) + " is broken");
      return std::nullopt;
    }
    Frame frame;
    frame.index = next_++;
    frame.gray = cv::Mat(32, 32, CV_8U, cv::Scalar(frame.index));
    if (frame.index == 0) info_.native_size = frame.gray.size();  // as sources learn it from the first frame
    return frame;
  }
  const SequenceInfo& info() const override { return info_; }

 private:
  int frames_, next_ = 0;
  bool fail_;
  SequenceInfo info_;
};

}  // namespace

TEST(ReadAheadSource, DeliversEveryFrameInOrderWithWhatTheSourceLearnt) {
  CountingSource source(100, /*fail=*/false);
  ReadAheadSource ahead(source, 3);
  EXPECT_EQ(ahead.info().expected_frames, 100);
  for (int i = 0; i < 100; ++i) {
    std::optional<Frame> frame = ahead.Next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->index, i);
    EXPECT_EQ(ahead.info().native_size, cv::Size(32, 32));
  }
  EXPECT_FALSE(ahead.Next());
  EXPECT_FALSE(ahead.Next());
}

TEST(ReadAheadSource, RethrowsTheSourcesErrorWhereItHappened) {
  CountingSource source(5, /*fail=*/true);
  ReadAheadSource ahead(source, 2);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(ahead.Next());
  EXPECT_THROW(ahead.Next(), InputError);
  EXPECT_FALSE(ahead.Next());
}

TEST(ReadAheadSource, StopsItsReaderWhenDestroyedEarly) {
  CountingSource source(1000000, /*fail=*/false);
  ReadAheadSource ahead(source, 4);
  ASSERT_TRUE(ahead.Next());
}  // the destructor must not wait for the million frames

}  // namespace vmap
