#include "vmap/sources/read_ahead_source.h"

#include <algorithm>

namespace vmap {

ReadAheadSource::ReadAheadSource(FrameSource& source, int frames)
    : source_(source),
      info_(source.info()),
      skipped_(source.skipped_frames()),
      queue_(static_cast<size_t>(std::max(1, frames))),
      reader_([this] { Read(); }) {}

ReadAheadSource::~ReadAheadSource() {
  queue_.Close();
  if (reader_.joinable()) reader_.join();
}

void ReadAheadSource::Read() {
  for (;;) {
    Item item;
    try {
      item.frame = source_.Next();
    } catch (...) {
      item.error = std::current_exception();
    }
    item.info = source_.info();
    item.skipped = source_.skipped_frames();
    const bool last = !item.frame;
    if (!queue_.Push(std::move(item)) || last) return;
  }
}

std::optional<Frame> ReadAheadSource::Next() {
  if (ended_) return std::nullopt;
  std::optional<Item> item = queue_.Pop();
  if (!item) {  // only after the destructor closed the queue
    ended_ = true;
    return std::nullopt;
  }
  info_ = std::move(item->info);
  skipped_ = item->skipped;
  if (item->error) {
    ended_ = true;
    std::rethrow_exception(item->error);
  }
  if (!item->frame) ended_ = true;
  return std::move(item->frame);
}

}  // namespace vmap
