#pragma once
// What every recording fuzz target does with its input: writes it to a file of the container's extension,
// opens it as vmap opens a recording, lists its topics, reads every message and decodes the images and
// cameras among them. Any InputError is the expected answer to bad bytes; a crash, a sanitizer report, another
// exception, a hang (-timeout) or an allocation past -rss_limit_mb is a bug.

#include <stdlib.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <opencv2/core.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/sources/recording_reader.h"
#include "vmap/sources/ros_image_messages.h"

namespace vmap::fuzz {

// Limits far below the defaults (and the 2 GB a fuzzer may take), for the same code paths at a fuzzer's pace.
inline RecordingLimits FuzzLimits() {
  RecordingLimits limits;
  limits.max_message_bytes = 16 << 20;
  limits.max_chunk_bytes = 32 << 20;
  limits.pass_bytes_floor = 64 << 20;
  limits.pass_records_floor = 1 << 16;
  return limits;
}

// A folder of this process's own for the inputs, removed at exit.
class ScratchFolder {
 public:
  ScratchFolder() {
    path_ = (access("/dev/shm", W_OK) == 0 ? std::string("/dev/shm") : std::string("/tmp")) + "/vmap-fuzz-XXXXXX";
    if (!mkdtemp(path_.data())) abort();
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

inline const std::string& Scratch() {
  static const ScratchFolder folder;
  static const bool quiet = (spdlog::set_level(spdlog::level::off), true);  // every input here warns of damage
  (void)quiet;
  return folder.path();
}

inline int FuzzRecording(const uint8_t* data, size_t size, const char* extension) {
  const std::string path = Scratch() + "/input" + extension;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  try {
    const std::unique_ptr<RecordingReader> reader = OpenRecording(path, FuzzLimits());
    std::map<std::string, std::string> types;
    for (const RecordingTopic& topic : reader->Topics()) types[topic.name] = topic.type;
    reader->Rewind();
    RecordedMessage message;
    for (int read = 0; read < 100000 && reader->Next({}, &message); ++read) {
      const std::string& type = types[message.topic];
      try {
        if (IsImageType(type)) {
          DecodeImageMessage(message.data.data(), message.data.size(), type, reader->encoding(), "message");
        } else if (NormalizedTypeName(type) == kCameraInfoType) {
          DecodeCameraInfo(message.data.data(), message.data.size(), reader->encoding(), "message");
        }
      } catch (const InputError&) {
      } catch (const cv::Exception&) {
        // OpenCV's refusal of one message: RecordingSource skips that message with a warning, as here.
      }
    }
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace vmap::fuzz
