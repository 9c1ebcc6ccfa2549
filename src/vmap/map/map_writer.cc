#include "vmap/map/map_writer.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/core/image_file.h"
#include "vmap/core/serial_worker.h"
#include "vmap/map/map_io.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

std::string LowerExtension(const std::string& path) {
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// A key image is the input's own file when the frame was decoded from an image file at its size: a copy is
// cheap and exactly the input. Other frames (video, resized) are written as PNG with OpenCV's default settings
// (zlib level 1, run-length strategy): faster than level 1 with the default strategy, for somewhat larger files,
// and still slow enough to need a thread of its own (docs/measurements/code-choices.md, "Writing key images").
// Only PNG and JPEG files are kept as they are, and only when their header gives the frame's size: ReadMap
// checks a key image's size from those headers.
bool KeepsSourceFile(const Frame& frame) {
  if (frame.source_path.empty() || frame.resized) return false;
  const std::string extension = LowerExtension(frame.source_path);
  if (extension != ".png" && extension != ".jpg" && extension != ".jpeg") return false;
  // A JPEG whose EXIF orientation turned it when decoded has another size in its header than the frame: a copy
  // would not be the frame ReadMap expects.
  const std::optional<cv::Size> size = KeyImageFileSize(frame.source_path);
  return size && *size == frame.gray.size();
}

std::string KeyImageFileName(const Frame& frame) {
  const std::string extension = KeepsSourceFile(frame) ? LowerExtension(frame.source_path) : ".png";
  return fmt::format("keys/{:06d}{}", frame.index, extension);
}

[[noreturn]] void CannotWrite(const fs::path& file, const std::string& reason) {
  throw InputError("cannot write '" + file.string() + "' (" + reason +
                   "); check the free space and the permissions of the output directory");
}

// A record of the evaluations' file: Evaluation's fields one after another, in this process's byte order (the
// file never leaves it). Not the struct as laid out in memory: its padding bytes are never initialised, and
// valgrind reported them written. `f(field)` for each field of `e`, in the record's order.
template <typename E, typename F>
constexpr void ForEachRecordField(E& e, F&& f) {
  f(e.key_frame);
  f(e.frame);
  f(e.similarity);
  f(e.num_tentative);
  f(e.num_verified);
  f(e.matched);
}
constexpr std::size_t RecordSize() {
  std::size_t size = 0;
  const Evaluation e;
  ForEachRecordField(e, [&](const auto& field) { size += sizeof field; });
  return size;
}
static_assert(RecordSize() == kEvaluationRecordSize);

std::array<char, kEvaluationRecordSize> EvaluationRecord(const Evaluation& e) {
  std::array<char, kEvaluationRecordSize> record;
  char* out = record.data();
  ForEachRecordField(e, [&](const auto& field) {
    std::memcpy(out, &field, sizeof field);
    out += sizeof field;
  });
  return record;
}
Evaluation EvaluationOfRecord(const char* in) {
  Evaluation e;
  ForEachRecordField(e, [&](auto& field) {
    std::memcpy(&field, in, sizeof field);
    in += sizeof field;
  });
  return e;
}

}  // namespace

// Writes key images on a thread of its own, so that encoding never stalls the builder, and with it the whole
// pipeline.
class MapWriter::KeyImageFiles {
 public:
  void Add(fs::path file, std::shared_ptr<const Frame> frame) {
    worker_.Post([file = std::move(file), frame = std::move(frame)] {
      if (KeepsSourceFile(*frame)) return CopyImageFile(frame->source_path, file, "key image");
      WriteImageFile(file, ColorImage(*frame), "key image");
    });
  }

  // Waits until every image queued so far is written; rethrows the first failure.
  void Flush() { worker_.Wait(); }

 private:
  SerialWorker worker_;
};

MapWriter::MapWriter(fs::path directory, std::optional<SnapshotTarget> snapshots)
    : directory_(std::move(directory)), snapshots_(std::move(snapshots)) {
  // Not create_directories: `directory` is or lies in a temporary output, and once an interruption has
  // removed that, nothing may bring it back (AtomicOutputDirectory::path()). It must exist.
  std::error_code ec;
  fs::create_directory(directory_ / "keys", ec);
  if (ec) CannotWrite(directory_ / "keys", ec.message());
  const fs::path spill = directory_ / kEvaluationsSpillFileName;
  evaluations_ = std::fopen(spill.c_str(), "w+b");
  if (!evaluations_) CannotWrite(spill, std::strerror(errno));
  key_images_ = std::make_unique<KeyImageFiles>();
}

MapWriter::~MapWriter() {
  key_images_.reset();  // joins its thread
  if (evaluations_) std::fclose(evaluations_);
  if (!finished_) {
    std::error_code ignored;
    fs::remove(directory_ / kEvaluationsSpillFileName, ignored);
  }
}

std::string MapWriter::AddKeyImage(std::shared_ptr<const Frame> frame) {
  std::string name = KeyImageFileName(*frame);
  key_images_->Add(directory_ / name, std::move(frame));
  return name;
}

void MapWriter::FlushKeyImages() { key_images_->Flush(); }

void MapWriter::AddEvaluation(const Evaluation& evaluation) {
  const std::array<char, kEvaluationRecordSize> record = EvaluationRecord(evaluation);
  if (std::fwrite(record.data(), record.size(), 1, evaluations_) != 1) {
    CannotWrite(directory_ / kEvaluationsSpillFileName, std::strerror(errno));
  }
  ++num_evaluations_;
}

EvaluationSource MapWriter::Evaluations() {
  if (std::fflush(evaluations_) != 0) CannotWrite(directory_ / kEvaluationsSpillFileName, std::strerror(errno));
  const fs::path spill = directory_ / kEvaluationsSpillFileName;
  const long count = num_evaluations_;
  return [spill, count](const std::function<void(const Evaluation&)>& fn) {
    std::ifstream in(spill, std::ios::binary);
    constexpr long kChunk = 4096;  // records read at once
    std::vector<char> chunk(kChunk * kEvaluationRecordSize);
    for (long done = 0; done < count;) {
      const long n = std::min(count - done, kChunk);
      in.read(chunk.data(), static_cast<std::streamsize>(n * kEvaluationRecordSize));
      if (!in) throw InputError("cannot read back '" + spill.string() + "', vmap's own file; was it removed?");
      for (long i = 0; i < n; ++i) fn(EvaluationOfRecord(chunk.data() + i * kEvaluationRecordSize));
      done += n;
    }
  };
}

void MapWriter::WriteMapAndCorrespondences(const VisualMap& map, const fs::path& directory) {
  // Both files go into a directory no reader sees before it is committed (or, for a library caller's own
  // folder, through a rename), so they are written in place.
  const auto write = [&](const fs::path& file, const std::function<void(std::ostream&)>& content) {
    const fs::path partial = file.parent_path() / ("." + file.filename().string() + ".partial");
    {
      std::ofstream out(partial, std::ios::binary | std::ios::trunc);
      if (!out) CannotWrite(file, std::strerror(errno));
      content(out);
      out.flush();
      if (!out) CannotWrite(file, std::strerror(errno));
    }
    std::error_code ec;
    fs::rename(partial, file, ec);
    if (ec) CannotWrite(file, ec.message());
  };
  WriteCameraMask(map, directory);
  write(directory / kCorrespondencesFileName, [&](std::ostream& out) { out << CorrespondencesBinary(map); });
  const EvaluationSource evaluations = Evaluations();
  write(directory / kMapFileName, [&](std::ostream& out) { WriteMapJson(out, map, evaluations); });
}

void MapWriter::Snapshot(const VisualMap& map) {
  if (!snapshots_) throw std::logic_error("MapWriter::Snapshot without a snapshot target");
  key_images_->Flush();
  AtomicOutputDirectory snapshot(snapshots_->final_path, snapshots_->policy);
  std::error_code ec;
  fs::create_directory(snapshot.path() / "keys", ec);
  if (ec) CannotWrite(snapshot.path() / "keys", ec.message());
  for (const KeyImage& key : map.key_images) {
    const fs::path from = directory_ / key.image_file, to = snapshot.path() / key.image_file;
    fs::create_hard_link(from, to, ec);
    if (ec) {
      ec.clear();
      fs::copy_file(from, to, ec);
      if (ec) CannotWrite(to, ec.message());
    }
  }
  WriteMapAndCorrespondences(map, snapshot.path());
  if (snapshots_->write_beside) snapshots_->write_beside(snapshot.path());
  snapshot.Commit();
}

void MapWriter::Finish(const VisualMap& map, std::vector<Evaluation>* read_back) {
  key_images_->Flush();
  WriteMapAndCorrespondences(map, directory_);
  if (read_back) {
    read_back->clear();
    read_back->reserve(num_evaluations_);
    Evaluations()([read_back](const Evaluation& e) { read_back->push_back(e); });
  }
  std::fclose(evaluations_);
  evaluations_ = nullptr;
  std::error_code ec;
  fs::remove(directory_ / kEvaluationsSpillFileName, ec);
  finished_ = true;
}

}  // namespace vmap
