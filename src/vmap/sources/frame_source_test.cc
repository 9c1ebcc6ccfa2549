#include "vmap/sources/frame_source.h"

#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "vmap/core/error.h"
#include "vmap/testing/option_error.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

const testing::SyntheticSequence& Sequence() {
  static const testing::SyntheticSequence sequence = [] {
    testing::SyntheticOptions options;
    options.num_frames = 12;
    return testing::RenderSyntheticSequence(options);
  }();
  return sequence;
}

std::vector<Frame> ReadAll(FrameSource& source) {
  std::vector<Frame> frames;
  while (auto frame = source.Next()) frames.push_back(std::move(*frame));
  return frames;
}

std::string OpenError(const std::string& path, const FrameSourceOptions& options = {}) {
  try {
    auto source = OpenFrameSource(path, options);
    ReadAll(*source);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Frames written as an MJPEG AVI: every frame is a JPEG, so one can be damaged on its own.
fs::path WriteMjpegVideo(const fs::path& path, const std::vector<cv::Mat>& frames) {
  cv::VideoWriter writer(path.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                         frames[0].size());
  EXPECT_TRUE(writer.isOpened());
  for (const cv::Mat& f : frames) writer.write(f);
  writer.release();
  return path;
}

}  // namespace

TEST(NaturalSort, DigitRunsCompareAsNumbers) {
  EXPECT_TRUE(NaturalLess("img2.png", "img10.png"));
  EXPECT_FALSE(NaturalLess("img10.png", "img2.png"));
  EXPECT_TRUE(NaturalLess("a1b2", "a1b10"));
  EXPECT_TRUE(NaturalLess("frame_9", "frame_10"));
  EXPECT_TRUE(NaturalLess("1", "01"));  // equal value: shorter first, so the order is total
  EXPECT_FALSE(NaturalLess("same", "same"));
  EXPECT_TRUE(NaturalLess("x99999999999999999999999", "x100000000000000000000000"));
  // Frames named by their times in seconds: the decimals compare as decimals.
  EXPECT_TRUE(NaturalLess("1700000000.05.png", "1700000000.5.png"));
  EXPECT_FALSE(NaturalLess("1700000000.9.png", "1700000000.15.png"));
  EXPECT_TRUE(NaturalLess("1700000000.15.png", "1700000000.9.png"));
  EXPECT_TRUE(NaturalLess("9.99.png", "10.05.png"));
  EXPECT_TRUE(NaturalLess("frame.9.png", "frame.10.png"));  // no number before the point: numbers
}

TEST(ImageFolder, ReadsInNaturalOrder) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path());
  auto source = OpenFrameSource(tmp.path().string());
  EXPECT_EQ(source->info().format, SourceFormat::kImageFolder);
  EXPECT_EQ(source->info().expected_frames, 12);
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 12u);
  EXPECT_EQ(frames[1].source_name, "frame_2.png");
  EXPECT_EQ(frames[9].source_name, "frame_10.png");
  cv::Mat expected;
  cv::cvtColor(Sequence().frames[9], expected, cv::COLOR_BGR2GRAY);
  EXPECT_LE(cv::norm(frames[9].gray, expected, cv::NORM_INF), 1.0);
  EXPECT_EQ(ColorImage(frames[9]).channels(), 3);
  // A frame's file replaced by a FIFO after the frame was read: its colour is not waited for (cv::imread by the path
  // blocked for ever on the FIFO's open), the grey frame is what there is.
  fs::remove(tmp.path() / "frame_10.png");
  ASSERT_EQ(mkfifo((tmp.path() / "frame_10.png").c_str(), 0600), 0);
  const cv::Mat from_grey = ColorImage(frames[9]);
  ASSERT_EQ(from_grey.type(), CV_8UC3);
  cv::Mat grey_again;
  cv::cvtColor(from_grey, grey_again, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(grey_again, frames[9].gray, cv::NORM_INF), 0.0);
}

// A calibration vmap found with the input that does not fit the frames is the file's fault, not the --camera option's
// (which the user never gave): an error of the input naming the file and the ways out.
TEST(ImageFolder, ACameraFoundWithTheInputThatDoesNotFitIsNotBlamedOnTheCameraOption) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path());
  std::ofstream(tmp.path() / "intrinsics.txt") << "fx 525\nfy 525\ncx 3080\ncy 236\n";
  try {
    OpenFrameSource(tmp.path().string(), FrameSourceOptions())->Next();
    ADD_FAILURE() << "a principal point outside the frames was accepted";
  } catch (const OptionError& error) {
    ADD_FAILURE() << "blamed on an option: " << error.what();
  } catch (const InputError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("intrinsics.txt"), std::string::npos) << what;
    EXPECT_NE(what.find("none: no camera"), std::string::npos) << what;
  }
  // Given as --camera, the same file is the option's error.
  FrameSourceOptions given;
  given.camera = (tmp.path() / "intrinsics.txt").string();
  EXPECT_THROW(OpenFrameSource(tmp.path().string(), given)->Next(), OptionError);
}

// A format given that the input is not is the format's error, naming the one the input looks like ("--format tum" on a
// video said only that its line 1 is no 'timestamp filename').
TEST(ImageFolder, AFormatTheInputIsNotIsTheFormatsError) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path());
  FrameSourceOptions options;
  options.format = SourceFormat::kTum;
  try {
    OpenFrameSource(tmp.path().string(), options);
    ADD_FAILURE() << "an image folder opened as TUM";
  } catch (const OptionError& error) {
    EXPECT_EQ(error.path(), "format");
    EXPECT_NE(std::string(error.what()).find("looks like images: give that format, or leave the format out"),
              std::string::npos)
        << error.what();
  }
}

TEST(ImageFolder, FirstLastStrideAndResize) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path());
  FrameSourceOptions options;
  options.first = 2;
  options.last = 9;
  options.stride = 3;
  options.resize = "160";
  auto source = OpenFrameSource(tmp.path().string(), options);
  EXPECT_EQ(source->info().expected_frames, 3);
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].source_index, 2);
  EXPECT_EQ(frames[2].source_index, 8);
  EXPECT_EQ(frames[2].index, 2);
  EXPECT_EQ(frames[0].gray.size(), cv::Size(160, 120));
  options = {};
  options.resize = "100x50";
  auto resized = OpenFrameSource(tmp.path().string(), options);
  EXPECT_EQ(resized->Next()->gray.size(), cv::Size(100, 50));
  options.resize = "big";
  EXPECT_THROW(options.Check(), InputError);
}

// A longest side is judged on the frames' own shape, not on an assumed 640x480: 12000 makes 800x100 frames 12000x1500
// (18 megapixels, allowed), though it would make 640x480 ones 12000x9000 (more than the 64 allowed); 40 makes them
// 40x5, refused naming their size.
TEST(ImageFolder, ALongestSideIsJudgedOnTheFramesOwnShape) {
  testing::ScopedTempDir tmp;
  for (int i = 0; i < 2; ++i) {
    cv::Mat wide(100, 800, CV_8UC1);
    cv::randu(wide, 0, 255);
    cv::imwrite((tmp.path() / ("frame_" + std::to_string(i) + ".png")).string(), wide);
  }
  FrameSourceOptions options;
  options.resize = "12000";
  EXPECT_NO_THROW(options.Check());
  EXPECT_EQ(OpenFrameSource(tmp.path().string(), options)->Next()->gray.size(), cv::Size(12000, 1500));
  options.resize = "40";
  EXPECT_NO_THROW(options.Check());
  const std::string error = OpenError(tmp.path().string(), options);
  EXPECT_NE(error.find("turns frames of 800x100 into 40x5"), std::string::npos) << error;
}

TEST(ImageFolder, FramesOfAnotherSizeAreResizedOrRejectedWhenStrict) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path());
  cv::Mat odd;
  cv::resize(Sequence().frames[4], odd, cv::Size(200, 100));
  cv::imwrite((tmp.path() / "frame_5.png").string(), odd);
  auto source = OpenFrameSource(tmp.path().string());
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 12u);
  EXPECT_EQ(frames[4].gray.size(), frames[0].gray.size());
  FrameSourceOptions strict;
  strict.strict = true;
  const std::string error = OpenError(tmp.path().string(), strict);
  EXPECT_NE(error.find("frame_5.png"), std::string::npos) << error;
  EXPECT_NE(error.find("200x100"), std::string::npos) << error;
}

TEST(ImageFolder, UnknownLayoutsAndEmptyFoldersAreClearErrors) {
  testing::ScopedTempDir tmp;
  EXPECT_NE(OpenError(tmp.path().string()).find("holds no images"), std::string::npos);
  std::ofstream(tmp.path() / "notes.txt") << "hello";
  EXPECT_NE(OpenError(tmp.path().string()).find("give its format"), std::string::npos);
  FrameSourceOptions video;
  video.format = SourceFormat::kVideo;
  EXPECT_EQ(testing::OptionErrorPath([&] { OpenFrameSource(tmp.path().string(), video); }), "format");
  EXPECT_NE(OpenError((tmp.path() / "missing").string()).find("does not exist"), std::string::npos);
  // The folder a video lies in, and a map folder given as a run: each named as what it is.
  std::ofstream(tmp.path() / "drive.MP4") << "not decoded: named only";
  EXPECT_NE(OpenError(tmp.path().string()).find("give it, e.g. '" + (tmp.path() / "drive.MP4").string() + "'"),
            std::string::npos)
      << OpenError(tmp.path().string());
  fs::create_directories(tmp.path() / "map/keys");
  std::ofstream(tmp.path() / "map/map.json") << "{}";
  EXPECT_NE(OpenError((tmp.path() / "map").string()).find("is a vmap map"), std::string::npos);
}

TEST(ImageFolder, UndecodableImageIsSkippedAndCounted) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path());
  std::ofstream(tmp.path() / "frame_3.png", std::ios::trunc) << "not a png";
  auto source = OpenFrameSource(tmp.path().string());
  EXPECT_EQ(ReadAll(*source).size(), 11u);
  EXPECT_EQ(source->skipped_frames(), 1);
}

TEST(ImageFolder, BadFramesAreSkippedWithAWarningAndCounted) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path());  // 12 frames of 320x240
  // Decode failures, degenerate sizes and too many pixels, among good frames and at the very start.
  cv::imwrite((tmp.path() / "frame_1.png").string(), cv::Mat(1, 1, CV_8U, cv::Scalar(7)));
  cv::imwrite((tmp.path() / "frame_3.png").string(), cv::Mat(500, 20, CV_8U, cv::Scalar(7)));
  cv::imwrite((tmp.path() / "frame_5.png").string(), cv::Mat(31, 400, CV_8U, cv::Scalar(7)));
  testing::WritePngHeader(tmp.path() / "frame_7.png", 40000, 40000);  // refused from its header
  testing::WritePngHeader(tmp.path() / "frame_8.png", 2, 3);          // a header and no data
  std::ofstream(tmp.path() / "frame_10.png", std::ios::trunc) << "";
  auto source = OpenFrameSource(tmp.path().string());
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 6u);
  EXPECT_EQ(source->skipped_frames(), 6);
  EXPECT_EQ(frames[0].source_name, "frame_2.png") << "the first good frame sets the sequence's size";
  EXPECT_EQ(source->info().frame_size, cv::Size(320, 240));
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].index, static_cast<int>(i));
    EXPECT_EQ(frames[i].gray.size(), cv::Size(320, 240));
  }
  // The pixel limit is an option: frames above it are skipped too.
  FrameSourceOptions small_limit;
  small_limit.max_frame_pixels = 100 * 100;
  cv::imwrite((tmp.path() / "frame_13.png").string(), cv::Mat(60, 80, CV_8UC3, cv::Scalar(1, 2, 3)));
  cv::imwrite((tmp.path() / "frame_14.png").string(), cv::Mat(90, 100, CV_8UC3, cv::Scalar(1, 2, 3)));
  auto limited = OpenFrameSource(tmp.path().string(), small_limit);
  const auto small_frames = ReadAll(*limited);
  ASSERT_EQ(small_frames.size(), 2u);
  EXPECT_EQ(small_frames[0].source_name, "frame_13.png");
  EXPECT_EQ(limited->skipped_frames(), 12);
}

// An entry named as an image that is no file to read is skipped and counted like a bad frame: a link loop once ended
// the whole run, a dangling link or a FIFO was left out without a word, a JPEG cut short was used half grey.
TEST(ImageFolder, EntriesThatAreNoFilesAreSkippedAndCounted) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path());                // 12 frames
  fs::create_symlink("frame_20.png", tmp.path() / "frame_20.png");  // a loop
  fs::create_symlink(tmp.path() / "nowhere.png", tmp.path() / "frame_21.png");
  ASSERT_EQ(mkfifo((tmp.path() / "frame_22.png").c_str(), 0600), 0);
  fs::create_symlink("loop", tmp.path() / "loop");  // not an image's name: not a frame
  // A JPEG cut short, which libjpeg would decode with its lower half grey.
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", Sequence().frames[0], jpeg);
  std::ofstream(tmp.path() / "frame_23.jpg", std::ios::binary)
      .write(reinterpret_cast<const char*>(jpeg.data()), static_cast<std::streamsize>(jpeg.size() / 2));
  auto source = OpenFrameSource(tmp.path().string());
  EXPECT_EQ(ReadAll(*source).size(), 12u);
  EXPECT_EQ(source->skipped_frames(), 4);
}

// Stamps that cannot be seconds (nanoseconds since 1970) are refused before any work: a map of them could not be read
// back. A timestamps file that is a FIFO is refused, not taken for no timestamps.
TEST(ImageFolder, TimestampsThatAreNoSecondsOrNoFileAreRefused) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path() / "frames");
  std::ofstream stamps(tmp.path() / "frames/timestamps.txt");
  for (int i = 1; i <= 12; ++i) stamps << "frame_" << i << ".png " << 1700000000000000000LL + i * 50000000LL << "\n";
  stamps.close();
  EXPECT_NE(OpenError((tmp.path() / "frames").string()).find("in nanoseconds or microseconds?"), std::string::npos)
      << OpenError((tmp.path() / "frames").string());
  fs::remove(tmp.path() / "frames/timestamps.txt");
  ASSERT_EQ(mkfifo((tmp.path() / "frames/timestamps.txt").c_str(), 0600), 0);
  EXPECT_NE(OpenError((tmp.path() / "frames").string()).find("timestamps"), std::string::npos);
}

// The times in timestamps.txt say the order the frames were taken in, where the names sort otherwise.
TEST(ImageFolder, FramesAreReadInTheOrderOfTheirTimesWhereTheNamesSortOtherwise) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path() / "frames");  // frame_1.png .. frame_12.png
  std::ofstream stamps(tmp.path() / "frames/timestamps.txt");
  for (int i = 1; i <= 12; ++i) stamps << "frame_" << i << ".png " << (i % 2 == 0 ? 100.0 + i : 200.0 + i) << "\n";
  stamps.close();
  const auto frames = ReadAll(*OpenFrameSource((tmp.path() / "frames").string()));
  ASSERT_EQ(frames.size(), 12u);
  EXPECT_EQ(frames.front().source_name, "frame_2.png");
  EXPECT_EQ(frames[5].source_name, "frame_12.png");
  EXPECT_EQ(frames[6].source_name, "frame_1.png");
  for (size_t i = 1; i < frames.size(); ++i) EXPECT_LT(frames[i - 1].timestamp, frames[i].timestamp) << i;
}

TEST(ImageFolder, AFolderOfOnlyBadFramesIsAClearError) {
  testing::ScopedTempDir tmp;
  cv::imwrite((tmp.path() / "a.png").string(), cv::Mat(1, 1, CV_8U));
  testing::WritePngHeader(tmp.path() / "b.png", 40000, 40000);
  const std::string error = OpenError(tmp.path().string());
  EXPECT_NE(error.find("none of the 2 images"), std::string::npos) << error;
}

TEST(Video, FramesOfADegenerateSizeAreAClearError) {
  testing::ScopedTempDir tmp;
  const fs::path video = WriteMjpegVideo(tmp.path() / "tiny.avi", std::vector<cv::Mat>(3, cv::Mat(16, 16, CV_8UC3)));
  const std::string error = OpenError(video.string());
  EXPECT_NE(error.find("tiny.avi' has frames of 16x16, smaller than 32 pixels"), std::string::npos) << error;
}

TEST(FrameSourceOptions, EveryOptionHasARange) {
  struct Case {
    std::function<void(FrameSourceOptions&)> change;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {[](FrameSourceOptions& o) { o.first = -1; }, "first -1 is less than 0"},
      {[](FrameSourceOptions& o) { o.last = -5; }, "last -5 is not a frame"},
      {[](FrameSourceOptions& o) { o.last = -2; }, "-1 for the end"},
      {[](FrameSourceOptions& o) { o.first = 10, o.last = 3; }, "last 3 is before first 10"},
      {[](FrameSourceOptions& o) { o.stride = 0; }, "stride 0 is less than 1"},
      {[](FrameSourceOptions& o) { o.resize = "100000x100000"; }, "resize 100000x100000: each side must be 32"},
      {[](FrameSourceOptions& o) { o.resize = "16x16"; }, "each side must be 32 to 16384"},
      {[](FrameSourceOptions& o) { o.resize = "16000x16000"; }, "more than 67108864 pixels"},
      {[](FrameSourceOptions& o) { o.resize = "100000"; }, "the longest side must be 32 to 16384"},
      {[](FrameSourceOptions& o) { o.resize = "-640"; }, "the longest side"},
      {[](FrameSourceOptions& o) { o.resize = "640x"; }, "is not WxH"},
      {[](FrameSourceOptions& o) { o.max_frame_pixels = 10; }, "max_frame_pixels"},
  };
  for (const Case& c : cases) {
    FrameSourceOptions options;
    c.change(options);
    try {
      options.Check();
      ADD_FAILURE() << "accepted: " << c.expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
    }
  }
  FrameSourceOptions to_the_end;
  to_the_end.last = -1;
  EXPECT_NO_THROW(to_the_end.Check());
}

TEST(FrameSourceOptions, ALongestSideThatMakesFramesDegenerateIsAnError) {
  testing::ScopedTempDir tmp;
  // Panoramic frames of 1000x40: a longest side of 100 would make them 100x4.
  for (int i = 0; i < 3; ++i) {
    cv::imwrite((tmp.path() / ("p" + std::to_string(i) + ".png")).string(), cv::Mat(40, 1000, CV_8U, cv::Scalar(i)));
  }
  FrameSourceOptions options;
  options.resize = "100";
  const std::string error = OpenError(tmp.path().string(), options);
  EXPECT_NE(error.find("turns frames of 1000x40 into 100x4"), std::string::npos) << error;
}

TEST(Tum, ReadsRgbTxtWithTimestamps) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path() / "rgb");
  {
    std::ofstream list(tmp.path() / "rgb.txt");
    list << "# color images\n# timestamp filename\n" << std::fixed << std::setprecision(6);
    for (int i = 0; i < 5; ++i) list << 1305031102.175304 + i / 30.0 << " rgb/frame_" << i + 1 << ".png\n";
  }
  auto source = OpenFrameSource(tmp.path().string());
  EXPECT_EQ(source->info().format, SourceFormat::kTum);
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 5u);
  EXPECT_NEAR(frames[3].timestamp - frames[0].timestamp, 0.1, 1e-6);

  std::ofstream(tmp.path() / "rgb.txt", std::ios::app) << "1305031103.0 rgb/missing.png\n";
  const std::string error = OpenError(tmp.path().string());
  EXPECT_NE(error.find("line 8"), std::string::npos) << error;
  EXPECT_NE(error.find("missing.png"), std::string::npos) << error;
}

TEST(Euroc, ReadsDataCsv) {
  testing::ScopedTempDir tmp;
  const fs::path cam = tmp.path() / "mav0" / "cam0";
  fs::create_directories(cam / "data");
  std::ofstream csv(cam / "data.csv");
  csv << "#timestamp [ns],filename\n";
  for (int i = 0; i < 4; ++i) {
    const long long ns = 1403636579763555584LL + i * 50000000LL;
    cv::imwrite((cam / "data" / (std::to_string(ns) + ".png")).string(), Sequence().frames[i]);
    csv << ns << "," << ns << ".png\n";
  }
  csv.close();
  auto source = OpenFrameSource(tmp.path().string());
  EXPECT_EQ(source->info().format, SourceFormat::kEuroc);
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_NEAR(frames[2].timestamp - frames[0].timestamp, 0.1, 1e-6);
}

// A timestamp is the whole field in integer nanoseconds: std::stoll read "12abc" as 12 and seconds as nanoseconds.
TEST(Euroc, ATimestampThatIsNoIntegerOfNanosecondsIsRefusedByItsLine) {
  for (const char* stamp : {"12abc", "1403636580.100000", "0x10", ""}) {
    testing::ScopedTempDir tmp;
    const fs::path cam = tmp.path() / "mav0" / "cam0";
    fs::create_directories(cam / "data");
    cv::imwrite((cam / "data" / "a.png").string(), Sequence().frames[0]);
    std::ofstream(cam / "data.csv") << "#timestamp [ns],filename\n" << stamp << ",a.png\n";
    const std::string error = OpenError(tmp.path().string());
    EXPECT_NE(error.find("line 2: '" + std::string(stamp) + "' is no timestamp in integer nanoseconds"),
              std::string::npos)
        << stamp << ": " << error;
  }
}

TEST(Kitti, ReadsImage0AndTimes) {
  testing::ScopedTempDir tmp;
  fs::create_directories(tmp.path() / "image_0");
  std::ofstream times(tmp.path() / "times.txt");
  for (int i = 0; i < 3; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    cv::imwrite((tmp.path() / "image_0" / name).string(), Sequence().frames[i]);
    times << 1.036e-01 * i << "\n";
  }
  times.close();
  auto source = OpenFrameSource(tmp.path().string());
  EXPECT_EQ(source->info().format, SourceFormat::kKitti);
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_NEAR(frames[2].timestamp, 0.2072, 1e-9);

  // An image missing from the sequence: each other image keeps the time of its own number.
  fs::rename(tmp.path() / "image_0/000001.png", tmp.path() / "000001.png");
  const auto gapped_frames = ReadAll(*OpenFrameSource(tmp.path().string()));
  ASSERT_EQ(gapped_frames.size(), 2u);
  EXPECT_EQ(gapped_frames[1].source_name, "000002.png");
  EXPECT_NEAR(gapped_frames[1].timestamp, 0.2072, 1e-9);
  fs::rename(tmp.path() / "000001.png", tmp.path() / "image_0/000001.png");

  // A times.txt line that is no time: the timestamps are ignored with a warning, and the frames are read; a calib.txt
  // value that is no number names itself.
  std::ofstream(tmp.path() / "times.txt") << "0\nnan\n0.2\n";
  auto untimed = OpenFrameSource(tmp.path().string());
  const auto untimed_frames = ReadAll(*untimed);
  ASSERT_EQ(untimed_frames.size(), 3u);
  EXPECT_LT(untimed_frames[2].timestamp, 0.0);
  std::ofstream(tmp.path() / "calib.txt") << "P0: nan 0 0 0 0 1 0 0 0 0 1 0\n";
  EXPECT_NE(OpenError(tmp.path().string()).find("P0's value 1, 'nan', is not a finite number"), std::string::npos)
      << OpenError(tmp.path().string());
}

TEST(Video, ReadsEveryFrameWithTimestamps) {
  testing::ScopedTempDir tmp;
  const fs::path video = WriteMjpegVideo(tmp.path() / "clip.avi", Sequence().frames);
  auto source = OpenFrameSource(video.string());
  EXPECT_EQ(source->info().format, SourceFormat::kVideo);
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 12u);
  EXPECT_NEAR(frames[5].timestamp, 0.5, 1e-6);
  EXPECT_EQ(frames[5].source_name, "frame_000005");
  EXPECT_EQ(frames[5].color.channels(), 3);
  EXPECT_EQ(source->skipped_frames(), 0);
}

TEST(Video, FirstLastAndStrideSelectTheSameFramesAsAFullRead) {
  testing::ScopedTempDir tmp;
  const fs::path video = WriteMjpegVideo(tmp.path() / "clip.avi", Sequence().frames);
  auto full = OpenFrameSource(video.string());
  const auto all = ReadAll(*full);
  FrameSourceOptions options;
  options.first = 1;
  options.last = 10;
  options.stride = 4;
  auto source = OpenFrameSource(video.string(), options);
  EXPECT_EQ(source->info().expected_frames, 3);
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const Frame& expected = all[1 + 4 * k];
    EXPECT_EQ(frames[k].index, k);
    EXPECT_EQ(frames[k].source_index, expected.source_index);
    EXPECT_EQ(frames[k].source_name, expected.source_name);
    EXPECT_DOUBLE_EQ(frames[k].timestamp, expected.timestamp);
    EXPECT_EQ(cv::norm(frames[k].color, expected.color, cv::NORM_INF), 0.0);
  }
}

TEST(Video, CorruptFrameInTheMiddleIsSkippedAndCounted) {
  testing::ScopedTempDir tmp;
  const fs::path video = WriteMjpegVideo(tmp.path() / "clip.avi", Sequence().frames);
  // Destroy the start-of-image marker of the 7th JPEG: that frame cannot be decoded.
  std::fstream file(video, std::ios::in | std::ios::out | std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  size_t pos = 0;
  for (int k = 0; k < 7; ++k) pos = bytes.find("\xFF\xD8\xFF", pos + 1);
  ASSERT_NE(pos, std::string::npos);
  for (size_t i = pos; i < pos + 600; ++i) bytes[i] = 0;
  file.seekp(0);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  file.close();
  auto source = OpenFrameSource(video.string());
  const auto frames = ReadAll(*source);
  EXPECT_GE(frames.size(), 10u);
  EXPECT_LT(frames.size(), 12u);
  EXPECT_EQ(source->skipped_frames(), 12 - static_cast<int>(frames.size()));
}

TEST(Video, GarbageOrTruncatedFilesAreClearErrors) {
  testing::ScopedTempDir tmp;
  std::ofstream(tmp.path() / "noise.mp4") << std::string(5000, 'x');
  const std::string error = OpenError((tmp.path() / "noise.mp4").string());
  EXPECT_NE(error.find("noise.mp4"), std::string::npos) << error;
  EXPECT_NE(error.find("cannot open video"), std::string::npos) << error;
}

TEST(SharedData, LabFloorVideo) {
  const fs::path shared = testing::SharedDir();
  if (shared.empty()) GTEST_SKIP() << "../shared is not present";
  FrameSourceOptions options;
  options.last = 59;
  auto source = OpenFrameSource((shared / "data/lab_floor/lab_floor.mp4").string(), options);
  const auto frames = ReadAll(*source);
  ASSERT_EQ(frames.size(), 60u);
  EXPECT_EQ(frames[0].gray.size(), cv::Size(640, 480));
  EXPECT_NEAR(frames[30].timestamp, 1.0, 1e-3);  // 30 fps
}

// The largest last frame the range allows reads to the end, as -1 does: last + 1 overflowed, and the range was empty.
TEST(SharedData, TheLargestLastFrameIsTheEnd) {
  const fs::path shared = testing::SharedDir();
  if (shared.empty()) GTEST_SKIP() << "../shared is not present";
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(Sequence(), tmp.path());
  for (const fs::path& input : {tmp.path(), shared / "data/lab_floor/lab_floor.mp4"}) {
    FrameSourceOptions options;
    options.first = 3;
    const long to_the_end = OpenFrameSource(input.string(), options)->info().expected_frames;
    options.last = std::numeric_limits<int>::max();
    ASSERT_NO_THROW(options.Check());
    EXPECT_EQ(OpenFrameSource(input.string(), options)->info().expected_frames, to_the_end) << input;
    EXPECT_GT(to_the_end, 0) << input;
  }
}

// vmap decodes videos with FFmpeg itself; its frames and timestamps must be those of cv::VideoCapture, so
// that a video and the same frames read through OpenCV give the same map.
TEST(SharedData, VideoFramesEqualOpenCvCapture) {
  const fs::path shared = testing::SharedDir();
  if (shared.empty()) GTEST_SKIP() << "../shared is not present";
  const std::string path = (shared / "data/lab_floor/lab_floor.mp4").string();
  FrameSourceOptions options;
  options.last = 39;
  auto source = OpenFrameSource(path, options);
  cv::VideoCapture capture(path, cv::CAP_FFMPEG);
  ASSERT_TRUE(capture.isOpened());
  EXPECT_EQ(source->info().expected_frames, 40);
  EXPECT_NEAR(source->info().fps, capture.get(cv::CAP_PROP_FPS), 1e-9);
  int compared = 0;
  while (auto frame = source->Next()) {
    cv::Mat expected;
    ASSERT_TRUE(capture.read(expected));
    EXPECT_EQ(cv::norm(frame->color, expected, cv::NORM_INF), 0.0) << "frame " << frame->index;
    EXPECT_NEAR(frame->timestamp, capture.get(cv::CAP_PROP_POS_MSEC) / 1000.0, 1e-9) << "frame " << frame->index;
    ++compared;
  }
  EXPECT_EQ(compared, 40);
}

// Phones store portrait video sideways with a display rotation; frames must come out upright, as
// cv::VideoCapture delivers them.
TEST(SharedData, RotatedVideosAreDeliveredUpright) {
  const fs::path shared = testing::SharedDir();
  if (shared.empty()) GTEST_SKIP() << "../shared is not present";
  if (std::system("ffmpeg -version > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "ffmpeg (scripts/install-deps.sh) is missing";
  testing::ScopedTempDir tmp;
  for (int degrees : {90, 180, 270}) {
    const fs::path rotated = tmp.path() / ("rotated_" + std::to_string(degrees) + ".mp4");
    const std::string command =
        "ffmpeg -nostdin -loglevel error -y -i \"" + (shared / "data/lab_floor/lab_floor.mp4").string() +
        "\" -frames:v 5 -c copy -metadata:s:v:0 rotate=" + std::to_string(degrees) + " \"" + rotated.string() + "\"";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    auto source = OpenFrameSource(rotated.string());
    cv::VideoCapture capture(rotated.string(), cv::CAP_FFMPEG);
    const auto frame = source->Next();
    cv::Mat expected;
    ASSERT_TRUE(frame.has_value() && capture.read(expected));
    EXPECT_EQ(frame->color.size(), degrees == 180 ? cv::Size(640, 480) : cv::Size(480, 640)) << degrees;
    ASSERT_EQ(frame->color.size(), expected.size()) << degrees;
    EXPECT_EQ(cv::norm(frame->color, expected, cv::NORM_INF), 0.0) << degrees;
    EXPECT_EQ(frame->gray.size(), frame->color.size());
  }
}

TEST(SharedData, EveryLayoutOpens) {
  const fs::path shared = testing::SharedDir();
  if (shared.empty()) GTEST_SKIP() << "../shared is not present";
  struct Case {
    std::string path;
    SourceFormat format;
    long frames;
  };
  for (const Case& c :
       {Case{"data/rccar_room/images", SourceFormat::kImageFolder, 329},
        Case{"data/rccar_room", SourceFormat::kImageFolder, 329}, Case{"data/redkitchen", SourceFormat::kTum, 1000},
        Case{"data/kitti07", SourceFormat::kKitti, 160}}) {
    auto source = OpenFrameSource((shared / c.path).string());
    EXPECT_EQ(source->info().format, c.format) << c.path;
    EXPECT_EQ(source->info().expected_frames, c.frames) << c.path;
    const auto first = source->Next();
    ASSERT_TRUE(first.has_value());
    EXPECT_GE(first->timestamp, 0.0) << c.path << ": timestamps are kept";
  }
}

}  // namespace vmap
