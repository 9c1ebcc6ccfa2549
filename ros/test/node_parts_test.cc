// The node's parts that need no ROS master: the mailbox, camera messages as frames, the odometry buffer, parameter
// names, the localization message's pose.

#include <chrono>
#include <cmath>
#include <thread>

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include "vmap/core/error.h"
#include "vmap/sources/recording_reader.h"
#include "vmap/sources/ros_image_messages.h"

#include "vmap_ros/camera_messages.h"
#include "vmap_ros/control_clock.h"
#include "vmap_ros/localization_message.h"
#include "vmap_ros/mailbox.h"
#include "vmap_ros/odometry_buffer.h"
#include "vmap_ros/parameter_reader.h"

namespace vmap::ros_node {
namespace {

// A message as a ShapeShifter subscription receives it: its bytes and its type.
template <typename Message>
topic_tools::ShapeShifter AsReceived(const Message& message) {
  std::vector<uint8_t> bytes = SerializeMessage(message);
  topic_tools::ShapeShifter shifter;
  shifter.morph(ros::message_traits::md5sum(message), ros::message_traits::datatype(message),
                ros::message_traits::definition(message), "0");
  ros::serialization::IStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
  shifter.read(stream);
  return shifter;
}

cv::Mat TestPattern() {
  cv::Mat image(120, 160, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.5);
  return image;
}

sensor_msgs::Image ImageMessage(const cv::Mat& pixels, const std::string& encoding, int padding = 0) {
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(12.5);
  image.header.frame_id = "cam";
  image.width = pixels.cols;
  image.height = pixels.rows;
  image.encoding = encoding;
  image.step = static_cast<uint32_t>(pixels.cols * pixels.elemSize() + padding);
  image.data.assign(image.step * image.height, 0);
  for (int y = 0; y < pixels.rows; ++y) {
    std::memcpy(&image.data[y * image.step], pixels.ptr(y), pixels.cols * pixels.elemSize());
  }
  return image;
}

TEST(Mailbox, KeepsTheNewestAndCountsWhatItPushedOut) {
  Mailbox<int> mailbox(1);
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(mailbox.Put(i));
  EXPECT_EQ(mailbox.Take(std::chrono::milliseconds(0)), 4);
  EXPECT_EQ(mailbox.TakeDropped(), 4u);
  EXPECT_EQ(mailbox.TakeDropped(), 0u);
  EXPECT_FALSE(mailbox.Take(std::chrono::milliseconds(1)).has_value());
}

TEST(Mailbox, HoldsItsCapacityInOrderAndDrainsAfterClose) {
  Mailbox<int> mailbox(3);
  for (int i = 0; i < 4; ++i) mailbox.Put(i);
  mailbox.Close();
  EXPECT_FALSE(mailbox.Put(9));
  EXPECT_FALSE(mailbox.closed_and_empty());
  EXPECT_EQ(mailbox.Take(std::chrono::milliseconds(0)), 1);
  EXPECT_EQ(mailbox.Take(std::chrono::milliseconds(0)), 2);
  EXPECT_EQ(mailbox.Take(std::chrono::milliseconds(0)), 3);
  EXPECT_TRUE(mailbox.closed_and_empty());
  EXPECT_EQ(mailbox.TakeDropped(), 1u);
}

TEST(Mailbox, TakeWakesWhenAnItemArrives) {
  Mailbox<int> mailbox(1);
  std::thread producer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    mailbox.Put(7);
  });
  EXPECT_EQ(mailbox.Take(std::chrono::seconds(30)), 7);
  producer.join();
}

TEST(CameraMessages, DecodesAnImageAsVmapDecodesItsRecording) {
  const cv::Mat pattern = TestPattern();
  for (const std::string encoding : {"bgr8", "rgb8", "mono8"}) {
    SCOPED_TRACE(encoding);
    cv::Mat pixels = pattern.clone();
    if (encoding == "rgb8") cv::cvtColor(pattern, pixels, cv::COLOR_BGR2RGB);
    if (encoding == "mono8") cv::cvtColor(pattern, pixels, cv::COLOR_BGR2GRAY);
    const sensor_msgs::Image message = ImageMessage(pixels, encoding, /*padding=*/3);
    const CameraImage image = DecodeCameraImage(AsReceived(message), "/cam/image_raw");
    const std::vector<uint8_t> bytes = SerializeMessage(message);
    const DecodedImage recorded =
        DecodeImageMessage(bytes.data(), bytes.size(), "sensor_msgs/Image", MessageEncoding::kRos1, "a message");
    EXPECT_EQ(cv::norm(image.gray, recorded.gray, cv::NORM_INF), 0.0);
    EXPECT_EQ(image.color.empty(), encoding == "mono8");
    if (!image.color.empty()) {
      EXPECT_EQ(cv::norm(image.color, pattern, cv::NORM_INF), 0.0);
    }
    EXPECT_DOUBLE_EQ(image.stamp, 12.5);
    EXPECT_EQ(image.header.frame_id, "cam");
  }
}

TEST(CameraMessages, DecodesACompressedImage) {
  const cv::Mat pattern = TestPattern();
  sensor_msgs::CompressedImage message;
  message.header.stamp = ros::Time(3.0);
  message.format = "png";
  cv::imencode(".png", pattern, message.data);
  const CameraImage image = DecodeCameraImage(AsReceived(message), "/cam/image_raw/compressed");
  EXPECT_EQ(cv::norm(image.color, pattern, cv::NORM_INF), 0.0);
  EXPECT_DOUBLE_EQ(image.stamp, 3.0);
}

TEST(CameraMessages, RefusesMalformedImagesAndOtherTypesNamingTheTopic) {
  const cv::Mat pattern = TestPattern();
  sensor_msgs::Image short_data = ImageMessage(pattern, "bgr8");
  short_data.data.resize(100);
  sensor_msgs::Image short_step = ImageMessage(pattern, "bgr8");
  short_step.step = 100;
  sensor_msgs::Image unknown = ImageMessage(pattern, "bgr8");
  unknown.encoding = "yuv422";
  sensor_msgs::CompressedImage garbage;
  garbage.format = "jpeg";
  garbage.data = {1, 2, 3};
  const auto refusal = [](const topic_tools::ShapeShifter& message) {
    try {
      DecodeCameraImage(message, "/cam/image_raw");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  EXPECT_NE(refusal(AsReceived(short_data)).find("needs more than its 100 bytes"), std::string::npos);
  EXPECT_NE(refusal(AsReceived(short_step)).find("with step 100"), std::string::npos);
  EXPECT_NE(refusal(AsReceived(unknown)).find("encoding 'yuv422'"), std::string::npos);
  EXPECT_NE(refusal(AsReceived(garbage)).find("cannot decode"), std::string::npos);
  const std::string twist = refusal(AsReceived(geometry_msgs::Twist()));
  EXPECT_NE(twist.find("/cam/image_raw carries geometry_msgs/Twist"), std::string::npos) << twist;
}

TEST(CameraMessages, ACameraInfoWithNanOrNoCalibration) {
  sensor_msgs::CameraInfo info;
  info.width = 640;
  info.height = 480;
  info.distortion_model = "plumb_bob";
  info.K = {500, 0, 320, 0, 500, 240, 0, 0, 1};
  const std::optional<Camera> camera = CameraFromInfo(info, "/cam/camera_info");
  ASSERT_TRUE(camera.has_value());
  EXPECT_EQ(camera->fx, 500.0);
  EXPECT_EQ(camera->size, cv::Size(640, 480));
  info.K[4] = std::nan("");
  EXPECT_THROW(CameraFromInfo(info, "/cam/camera_info"), InputError);
  info.K = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  EXPECT_FALSE(CameraFromInfo(info, "/cam/camera_info").has_value());  // uncalibrated
}

TEST(OdometryBuffer, InterpolatesBetweenSamplesAndGivesNoneOutsideThem) {
  OdometryBuffer buffer(10.0, 0.5);
  EXPECT_FALSE(buffer.At(1.0).has_value());
  buffer.Add({1.0, 0.0, 0.0, 0.0});
  buffer.Add({2.0, 1.0, 0.0, 0.2});
  buffer.Add({1.5, 9.0, 9.0, 9.0});  // older than the newest: ignored
  const std::optional<OdometrySample> middle = buffer.At(1.5);
  ASSERT_TRUE(middle.has_value());
  EXPECT_NEAR(middle->x, 0.5, 1e-12);
  EXPECT_NEAR(middle->yaw, 0.1, 1e-12);
  EXPECT_FALSE(buffer.At(0.5).has_value());  // before the odometry
  ASSERT_TRUE(buffer.At(2.3).has_value());   // a frame a little newer: the last sample
  EXPECT_EQ(buffer.At(2.3)->x, 1.0);
  EXPECT_FALSE(buffer.At(2.6).has_value());  // odometry that stopped
  // A stray stamp from the future, then the odometry as before: read anew, not ignored for good.
  EXPECT_FALSE(buffer.Add({1e6, 5.0, 5.0, 0.0}));
  EXPECT_TRUE(buffer.Add({2.5, 2.0, 0.0, 0.0}));
  EXPECT_FALSE(buffer.Add({2.6, 2.1, 0.0, 0.0}));
  ASSERT_TRUE(buffer.At(2.55).has_value());
  EXPECT_NEAR(buffer.At(2.55)->x, 2.05, 1e-12);
}

// ~odom_wait: a frame newer than the newest sample waits for the sample of its time while the odometry comes (the
// simulator publishes it just before the frame, on another connection: read before it came, the frame took the sample
// before it, and two runs of one trial drove apart), and not at all once the odometry has stopped.
TEST(OdometryBuffer, AFrameWaitsForTheOdometryOfItsTimeWhileItComes) {
  OdometryBuffer buffer(10.0, 0.5);
  buffer.Add({1.0, 0.0, 0.0, 0.0});
  std::thread sender([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    buffer.Add({1.1, 0.5, 0.0, 0.0});
  });
  const auto start = std::chrono::steady_clock::now();
  buffer.WaitFor(1.1, 30.0);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  sender.join();
  EXPECT_LT(waited, 20.0) << "woken by the sample, not the timeout";
  ASSERT_TRUE(buffer.At(1.1).has_value());
  EXPECT_EQ(buffer.At(1.1)->x, 0.5) << "the sample of the frame's time, not the one before it";
  // Odometry that stopped (the newest 0.5 s or more before the frame): no wait.
  const auto stopped = std::chrono::steady_clock::now();
  buffer.WaitFor(5.0, 30.0);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - stopped).count(), 20.0);
}

// The controller's time follows the camera's stamps while they advance; where they go back or stand still it follows
// the wall clock, so that a robot lost then still slows to a stop within lost_stop.
TEST(ControlClock, FollowsTheCameraWhileItAdvancesElseTheWallClock) {
  ControlClock clock;
  bool by_wall = true;
  EXPECT_DOUBLE_EQ(clock.Tick(100.0, 5000.0, &by_wall), 100.0);
  EXPECT_FALSE(by_wall);
  EXPECT_NEAR(clock.Tick(100.05, 5000.9, &by_wall), 100.05, 1e-9) << "the camera's clock, not the wall's";
  EXPECT_FALSE(by_wall);
  // A bag played again from its start: 1000 s back. The frames keep coming 50 ms apart on the wall clock.
  double time = 0.0;
  for (int i = 1; i <= 20; ++i)
    time = clock.Tick(i == 1 ? -900.0 : -900.0 + 0.05 * (i - 1), 5000.9 + 0.05 * i, &by_wall);
  EXPECT_NEAR(time, 100.05 + 0.05 + 19 * 0.05, 1e-9) << "one wall step, then the camera's again";
  // Stamps of 0 (/use_sim_time without /clock): the wall clock's steps.
  ControlClock sim_time;
  sim_time.Tick(0.0, 10.0, &by_wall);
  for (int i = 1; i <= 40; ++i) time = sim_time.Tick(0.0, 10.0 + 0.05 * i, &by_wall);
  EXPECT_TRUE(by_wall);
  EXPECT_NEAR(time, 2.0, 1e-9);
  // A jump forward is a gap of at most kMaxControlStep; one stamp twice and a wall clock that stood still advance
  // by kMinControlStep.
  ControlClock jumps;
  jumps.Tick(1.0, 1.0, &by_wall);
  EXPECT_DOUBLE_EQ(jumps.Tick(1e9, 1.1, &by_wall), 1.0 + kMaxControlStep);
  EXPECT_FALSE(by_wall);
  EXPECT_DOUBLE_EQ(jumps.Tick(1e9, 1.1, &by_wall), 1.0 + kMaxControlStep + kMinControlStep);
  EXPECT_TRUE(by_wall);
  EXPECT_DOUBLE_EQ(jumps.Tick(std::nan(""), std::nan(""), &by_wall), 1.0 + kMaxControlStep + 2 * kMinControlStep);
}

TEST(Parameters, AreTheFlagsNamesWithUnderscores) {
  EXPECT_EQ(ParameterName("--min-link-share"), "min_link_share");
  EXPECT_EQ(ParameterName("!--no-step-back"), "no_step_back");
  EXPECT_EQ(ParameterName("-t,--tau"), "tau");
  EXPECT_EQ(ParameterName("input"), "");  // a positional argument
  EXPECT_EQ(ParameterName(""), "");
}

TEST(LocalizationMessage, CarriesTheTargetsPoseAsAQuaternion) {
  LocalizationResult result;
  result.status = LocalizationStatus::kTracking;
  result.key = 2;
  result.next_key = 3;
  result.to_next.key = 3;
  result.to_next.pose.valid = true;
  const double angle = 0.3;  // about the camera's y axis (down): a turn
  result.to_next.pose.R =
      cv::Matx33d(std::cos(angle), 0, std::sin(angle), 0, 1, 0, -std::sin(angle), 0, std::cos(angle));
  result.to_next.pose.t = cv::Vec3d(0.0, 0.0, 1.0);
  result.motion_steps = 3;
  std_msgs::Header header;
  header.frame_id = "cam";
  const vmap_ros::Localization message = LocalizationMessage(header, result, {0, 1, 2, 3, 4}, ControlSummary{});
  EXPECT_TRUE(message.pose_valid);
  EXPECT_NEAR(message.pose.orientation.y, std::sin(angle / 2), 1e-12);
  EXPECT_NEAR(message.pose.orientation.w, std::cos(angle / 2), 1e-12);
  EXPECT_EQ(message.pose.position.z, 1.0);
  EXPECT_EQ(message.goal, 4);
  EXPECT_EQ(message.route_length, 5);
  EXPECT_EQ(message.status, vmap_ros::Localization::TRACKING);
  EXPECT_EQ(message.status_name, "tracking");
  EXPECT_EQ(message.motion_steps, 3);
}

}  // namespace
}  // namespace vmap::ros_node
