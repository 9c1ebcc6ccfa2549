#pragma once
// What the readers of the one-file recordings (ros1_bag_reader.cc, mcap_reader.cc) share: messages read in stored
// order, one chunk in memory at a time, and the topics from the index the file may end with (a ROS 1 bag's index,
// an MCAP file's summary) or, when it has none (a recording cut short), counted by reading every message.

#include <set>
#include <string>
#include <vector>

#include "vmap/sources/recording_reader.h"

namespace vmap {

class IndexedFileReader : public RecordingReader {
 public:
  bool Next(const std::set<std::string>& topics, RecordedMessage* message) final {
    return NextMessage(&topics, message);
  }

  std::vector<RecordingTopic> Topics() final {
    std::vector<RecordingTopic> indexed;
    if (TopicsFromIndex(&indexed)) return indexed;
    Rewind();
    std::vector<RecordingTopic> list = CountTopicsByReading([this](RecordedMessage* message, std::string* type) {
      if (!NextMessage(nullptr, message)) return false;
      *type = message->type;
      return true;
    });
    Rewind();
    return list;
  }

 protected:
  // The topics as the index at the file's end counts them, without reading the chunks; false when the file has no
  // index or it does not add up (the messages are then counted).
  virtual bool TopicsFromIndex(std::vector<RecordingTopic>* topics) = 0;
  // The next message on `topics` (nullptr: every message, for a count), in stored order, with its type; false at
  // the end.
  virtual bool NextMessage(const std::set<std::string>* topics, RecordedMessage* message) = 0;
};

}  // namespace vmap
