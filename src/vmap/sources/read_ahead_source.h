#pragma once
// A frame source read on a thread of its own, a few frames ahead of its consumer: decoding then overlaps with
// what the consumer does with each frame (MapBuilder::Add runs Algorithm 1 on the consumer's thread).

#include <exception>
#include <memory>
#include <thread>

#include "vmap/core/bounded_queue.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

class ReadAheadSource : public FrameSource {
 public:
  // Reads `source` (which must outlive this) on a new thread, at most `frames` frames ahead.
  ReadAheadSource(FrameSource& source, int frames);
  // Stops the reader; waits for a read in progress (a live source returns within its stream timeout).
  ~ReadAheadSource() override;

  // The next frame, in order; rethrows the error the source threw, at the frame where it threw it.
  std::optional<Frame> Next() override;
  // As the source described itself when it delivered the last frame taken (read on the reader thread, handed
  // over with the frame: no data race with the reader).
  const SequenceInfo& info() const override { return info_; }
  int skipped_frames() const override { return skipped_; }

 private:
  struct Item {
    std::optional<Frame> frame;  // nullopt: the end, or `error`
    SequenceInfo info;
    int skipped = 0;
    std::exception_ptr error;
  };
  void Read();

  FrameSource& source_;
  SequenceInfo info_;
  int skipped_ = 0;
  bool ended_ = false;
  BoundedQueue<Item> queue_;
  std::thread reader_;  // last: starts after every other member exists
};

}  // namespace vmap
