#include "vmap/sources/recording_source.h"

#include <map>
#include <set>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/sources/internal.h"
#include "vmap/sources/message_buffer.h"
#include "vmap/sources/ros_image_messages.h"

namespace vmap {
namespace {

// Messages are stored by receive time; a camera's stamps can be out of that order by a few frames (several
// publishers, a driver's queue). Frames are delivered in stamp order within a window of this many messages,
// holding at most kReorderBytes of them (at least one): a window of the largest frames would otherwise hold
// gigabytes.
constexpr size_t kReorderWindow = 8;
constexpr size_t kReorderBytes = size_t{64} << 20;

std::string ListImageTopics(const std::vector<RecordingTopic>& topics) {
  std::string list;
  for (const RecordingTopic& topic : topics) {
    if (IsImageType(topic.type)) {
      list += fmt::format("\n  {} ({}, {} messages)", topic.name, topic.type, topic.message_count);
    }
  }
  return list;
}

const RecordingTopic* FindTopic(const std::vector<RecordingTopic>& topics, const std::string& name) {
  for (const RecordingTopic& topic : topics) {
    if (topic.name == name) return &topic;
  }
  return nullptr;
}

std::string MessageName(long index, const std::string& topic, const std::string& path) {
  return fmt::format("message {} of {} in '{}'", index, topic, path);
}

// Messages per second of log time; 0 with fewer than two messages or no time between them.
double MessageRate(const RecordingTopic& topic) {
  if (topic.message_count < 2 || topic.last_time_ns <= topic.first_time_ns) return 0.0;
  return (topic.message_count - 1) * 1e9 / static_cast<double>(topic.last_time_ns - topic.first_time_ns);
}

class RecordingSource : public FrameSource {
 public:
  RecordingSource(std::unique_ptr<RecordingReader> reader, const RecordingTopic& topic, const std::string& path,
                  const FrameSourceOptions& options)
      : reader_(std::move(reader)), topic_(topic), topics_{topic.name}, options_(options) {
    info_.path = path;
    info_.format = SourceFormat::kRecording;
    if (topic.message_count == 0) {
      throw InputError(fmt::format("image topic {} of recording '{}' has no messages; `vmap info {}` lists its topics",
                                   topic.name, path, path));
    }
    if (options.first >= topic.message_count) {
      throw OptionError("first", fmt::format("{} leaves none of the {} frames of {} in '{}'", options.first,
                                             topic.message_count, topic.name, path));
    }
    long end = options.last >= 0 ? std::min<long>(static_cast<long>(options.last) + 1, topic.message_count)
                                 : topic.message_count;
    info_.expected_frames = end > options.first ? (end - options.first + options.stride - 1) / options.stride : 0;
    info_.fps = MessageRate(topic);
    if (info_.fps > kMaxFramesPerSecond) {
      spdlog::warn("{}: {} has {} messages within {} ns, which no camera sends; its frame rate is left unknown", path,
                   topic.name, topic.message_count, topic.last_time_ns - topic.first_time_ns);
      info_.fps = 0.0;
    }
  }

  std::optional<Frame> Next() override {
    for (;;) {
      if (options_.last >= 0 && position_ > options_.last) return End();
      Fill();
      if (pending_.empty()) return End();
      auto next = pending_.begin();
      const double stamp = next->first;
      RecordedMessage message = std::move(next->second);
      pending_.erase(next);
      pending_bytes_ -= message.data.size();
      if (stamp < last_stamp_ && out_of_order_warnings_++ == 0) {
        spdlog::warn("{}: {} has stamps out of order by more than {} messages; those frames keep their stored order",
                     info_.path, topic_.name, kReorderWindow);
      }
      last_stamp_ = std::max(last_stamp_, stamp);
      const long index = position_++;
      if (index < options_.first || (index - options_.first) % options_.stride != 0) continue;
      DecodedImage image;
      const std::string name = MessageName(index, topic_.name, info_.path);
      // Each message by its own connection's type: a topic may have had publishers of either image type.
      const std::string& type = message.type.empty() ? topic_.type : message.type;
      if (!IsImageType(type)) {
        ++skipped_;
        spdlog::warn("{} is a {}, not an image; skipping it", name, type);
        continue;
      }
      try {
        image = DecodeImageMessage(message.data.data(), message.data.size(), type, reader_->encoding(), name);
      } catch (const InputError& error) {
        ++skipped_;
        spdlog::warn("{}; skipping it", error.what());
        continue;
      } catch (const cv::Exception& error) {
        // A malformed message OpenCV refuses (a step it cannot take): that message, not the recording.
        ++skipped_;
        spdlog::warn("{} cannot be decoded ({}); skipping it", name, LibraryMessage(error));
        continue;
      }
      const std::string size_problem = FrameSizeProblem(image.gray.size(), options_);
      if (!size_problem.empty()) {
        ++skipped_;
        spdlog::warn("{}: frame {} is {}x{}, {}; skipping it", info_.path, index, image.gray.cols, image.gray.rows,
                     size_problem);
        continue;
      }
      Frame frame;
      frame.gray = std::move(image.gray);
      frame.color = std::move(image.color);
      frame.index = delivered_++;
      frame.source_index = static_cast<int>(index);
      frame.source_name = fmt::format("frame_{:06d}", index);
      frame.timestamp = stamp;
      internal::FitToSequence(frame, &info_, options_, &size_warnings_);
      return frame;
    }
  }

  const SequenceInfo& info() const override { return info_; }
  int skipped_frames() const override { return skipped_; }

 private:
  std::optional<Frame> End() const {
    if (delivered_ == 0) {
      throw InputError(fmt::format("none of the {} messages of {} read from '{}' could be used{}; check the recording",
                                   position_, topic_.name, info_.path,
                                   skipped_ > 0 ? " (see the warnings above)" : " (none is there from --first on)"));
    }
    return std::nullopt;
  }

  // Reads messages until the window is full or the recording ends. Damage ends the recording with a warning
  // once frames came before it, and is an error otherwise.
  void Fill() {
    while (!ended_ && pending_.size() < kReorderWindow && (pending_.empty() || pending_bytes_ < kReorderBytes)) {
      RecordedMessage message;
      try {
        if (!reader_->Next(topics_, &message)) {
          ended_ = true;
          break;
        }
      } catch (const RecordingLimitExceeded&) {
        throw;  // crafted or damaged beyond use: not a recording cut short whose frames before the cut count
      } catch (const InputError& error) {
        ended_ = true;
        if (read_ == 0) throw;
        spdlog::warn("{}; using the {} messages of {} before it", error.what(), read_, topic_.name);
        break;
      }
      double stamp = -1.0;
      try {
        MessageBuffer header(message.data.data(), message.data.size(), reader_->encoding(),
                             MessageName(read_, topic_.name, info_.path));
        if (reader_->encoding() == MessageEncoding::kRos1) header.U32();  // seq
        const uint32_t seconds = header.U32();
        const uint32_t nanoseconds = header.U32();
        stamp = seconds + nanoseconds * 1e-9;
      } catch (const InputError&) {
        // Decoding the message says what is wrong with it, if it is ever selected.
      }
      // A driver that never sets the stamp: the time the recorder received the message.
      if (stamp <= 0.0) stamp = message.log_time_ns * 1e-9;
      ++read_;
      pending_bytes_ += message.data.size();
      pending_.emplace(stamp, std::move(message));
    }
  }

  std::unique_ptr<RecordingReader> reader_;
  RecordingTopic topic_;
  std::set<std::string> topics_;
  FrameSourceOptions options_;
  SequenceInfo info_;
  std::multimap<double, RecordedMessage> pending_;
  size_t pending_bytes_ = 0;
  bool ended_ = false;
  long read_ = 0;
  long position_ = 0;
  int delivered_ = 0;
  int skipped_ = 0;
  int size_warnings_ = 0;
  int out_of_order_warnings_ = 0;
  double last_stamp_ = -1e300;
};

std::optional<Camera> ReadCameraTopic(const std::string& path, const std::string& camera_topic,
                                      const RecordingLimits& limits) {
  std::unique_ptr<RecordingReader> reader = OpenRecording(path, limits);
  RecordedMessage message;
  if (!reader->Next({camera_topic}, &message)) return std::nullopt;
  const std::string what = MessageName(0, camera_topic, path);
  std::optional<Camera> camera = DecodeCameraInfo(message.data.data(), message.data.size(), reader->encoding(), what);
  if (camera)
    camera->origin = path + " " + camera_topic;
  else
    spdlog::warn("{} holds no calibration (K is zero); the frames have no camera", what);
  return camera;
}

}  // namespace

std::string ChooseImageTopic(const std::vector<RecordingTopic>& topics, const std::string& requested,
                             const std::string& path) {
  const std::string images = ListImageTopics(topics);
  if (!requested.empty()) {
    const RecordingTopic* topic = FindTopic(topics, requested);
    if (topic && IsImageType(topic->type)) return requested;
    const std::string problem = topic ? "is a " + topic->type + " topic, not an image topic" : "is not in it";
    throw InputError(fmt::format("--topic {}: {} recording '{}'; {}", requested, problem, path,
                                 images.empty() ? "it has no image topic" : "its image topics are:" + images));
  }
  const std::string* only = nullptr;
  for (const RecordingTopic& topic : topics) {
    if (!IsImageType(topic.type)) continue;
    if (only) {
      throw InputError(
          fmt::format("recording '{}' has several image topics; choose one with --topic:{}", path, images));
    }
    only = &topic.name;
  }
  if (!only) {
    throw InputError(
        fmt::format("recording '{}' has no image topic (sensor_msgs/Image or sensor_msgs/"
                    "CompressedImage); `vmap info {}` lists its topics",
                    path, path));
  }
  return *only;
}

std::string CameraInfoTopicFor(const std::string& image_topic) {
  std::string base = image_topic;
  for (const char* transport : {"/compressed", "/compressedDepth", "/theora", "/zstd"}) {
    const std::string suffix = transport;
    if (base.size() > suffix.size() && base.compare(base.size() - suffix.size(), suffix.size(), suffix) == 0) {
      base.resize(base.size() - suffix.size());
      break;
    }
  }
  const size_t slash = base.rfind('/');
  return (slash == std::string::npos ? std::string() : base.substr(0, slash + 1)) + "camera_info";
}

std::vector<RecordingTopicSummary> DescribeRecording(const std::string& path) {
  std::unique_ptr<RecordingReader> reader = OpenRecording(path);
  std::vector<RecordingTopicSummary> summaries;
  std::map<std::string, size_t> image_topics;  // not yet sized -> its summary
  for (const RecordingTopic& topic : reader->Topics()) {
    RecordingTopicSummary summary;
    summary.topic = topic;
    summary.rate_hz = MessageRate(topic);
    if (IsImageType(topic.type) && topic.message_count > 0) image_topics[topic.name] = summaries.size();
    summaries.push_back(summary);
  }
  // The first image of every image topic, in one pass however many topics the recording lists.
  std::set<std::string> wanted;
  for (const auto& [name, index] : image_topics) wanted.insert(name);
  reader->Rewind();
  RecordedMessage message;
  while (!wanted.empty() && reader->Next(wanted, &message)) {
    RecordingTopicSummary& summary = summaries[image_topics.at(message.topic)];
    wanted.erase(message.topic);
    try {
      summary.image_size = ImageMessageSize(message.data.data(), message.data.size(), summary.topic.type,
                                            reader->encoding(), MessageName(0, message.topic, path));
    } catch (const InputError& error) {
      spdlog::warn("{}", error.what());
    } catch (const cv::Exception& error) {
      spdlog::warn("{} cannot be decoded ({})", MessageName(0, message.topic, path), LibraryMessage(error));
    }
  }
  return summaries;
}

std::string FormatRecordingTopics(const std::string& path, const std::vector<RecordingTopicSummary>& topics) {
  std::string text = fmt::format("recording {}\n{:<40} {:<32} {:>9} {:>9}  {}\n", path, "topic", "type", "messages",
                                 "rate Hz", "image");
  for (const RecordingTopicSummary& summary : topics) {
    const std::string size =
        summary.image_size.area() > 0 ? fmt::format("{}x{}", summary.image_size.width, summary.image_size.height) : "";
    text += fmt::format("{:<40} {:<32} {:>9} {:>9.2f}  {}\n", summary.topic.name, summary.topic.type,
                        summary.topic.message_count, summary.rate_hz, size);
  }
  return text;
}

namespace internal {

std::unique_ptr<FrameSource> OpenRecordingSource(const std::string& path, const FrameSourceOptions& options,
                                                 std::optional<Camera>* camera) {
  const RecordingLimits limits = RecordingLimits::ForFrames(options.max_frame_pixels);
  std::unique_ptr<RecordingReader> reader = OpenRecording(path, limits);
  const std::vector<RecordingTopic> topics = reader->Topics();
  const std::string name = ChooseImageTopic(topics, options.topic, path);
  if (camera) {
    const std::string camera_topic = options.camera_topic.empty() ? CameraInfoTopicFor(name) : options.camera_topic;
    const RecordingTopic* info = FindTopic(topics, camera_topic);
    if (info && NormalizedTypeName(info->type) != kCameraInfoType) {
      throw InputError(
          fmt::format("camera topic {} of recording '{}' is a {} topic, not sensor_msgs/CameraInfo; "
                      "name the right one with --camera-topic",
                      camera_topic, path, info->type));
    }
    if (!info && !options.camera_topic.empty()) {
      throw InputError(fmt::format("--camera-topic {} is not in recording '{}'; `vmap info {}` lists its topics",
                                   camera_topic, path, path));
    }
    if (info && info->message_count > 0) *camera = ReadCameraTopic(path, camera_topic, limits);
    if (!info) spdlog::info("{}: no {} topic; the frames have no camera unless --camera gives one", path, camera_topic);
  }
  return std::make_unique<RecordingSource>(std::move(reader), *FindTopic(topics, name), path, options);
}

}  // namespace internal
}  // namespace vmap
