#include "vmap/simulation/plane_renderer.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace vmap {
namespace {

std::shared_ptr<const Texture> Plain(cv::Scalar colour, cv::Size size = cv::Size(64, 64)) {
  return std::make_shared<Texture>(cv::Mat(size, CV_8UC3, colour));
}

PinholeView Camera() {
  PinholeView view;
  view.K = cv::Matx33d(100, 0, 79.5, 0, 100, 59.5, 0, 0, 1);
  view.size = cv::Size(160, 120);
  return view;  // at the origin, looking along +z
}

TEST(PlaneRenderer, AQuadLandsWherePerspectivePutsIt) {
  // A 2 m square 4 m ahead, its left half red and its right half green: x in [-1, 1] m -> 25 px either side.
  cv::Mat image(64, 64, CV_8UC3, cv::Scalar(0, 0, 255));
  image.colRange(32, 64).setTo(cv::Scalar(0, 255, 0));
  const TexturedPolygon quad =
      TexturedQuad({-1, -1, 4}, {1, -1, 4}, {1, 1, 4}, {-1, 1, 4}, std::make_shared<Texture>(image));
  RenderOptions options;
  options.mipmaps = false;
  const cv::Mat frame = RenderPolygons({quad}, Camera(), options);
  EXPECT_EQ(frame.at<cv::Vec3b>(60, 65), cv::Vec3b(0, 0, 255));   // left of centre: red
  EXPECT_EQ(frame.at<cv::Vec3b>(60, 95), cv::Vec3b(0, 255, 0));   // right: green
  EXPECT_EQ(frame.at<cv::Vec3b>(60, 50), cv::Vec3b(40, 40, 40));  // beyond the quad's edge (x = 54.5): background
  EXPECT_EQ(frame.at<cv::Vec3b>(60, 110), cv::Vec3b(40, 40, 40));
  EXPECT_EQ(frame.at<cv::Vec3b>(30, 79), cv::Vec3b(40, 40, 40));  // above it (y = 34.5)
}

TEST(PlaneRenderer, TheNearestQuadWins) {
  const TexturedPolygon far = TexturedQuad({-10, -10, 8}, {10, -10, 8}, {10, 10, 8}, {-10, 10, 8}, Plain({255, 0, 0}));
  const TexturedPolygon near = TexturedQuad({-1, -1, 3}, {1, -1, 3}, {1, 1, 3}, {-1, 1, 3}, Plain({0, 0, 255}));
  for (const auto& order : {std::vector<TexturedPolygon>{far, near}, std::vector<TexturedPolygon>{near, far}}) {
    const cv::Mat frame = RenderPolygons(order, Camera());
    EXPECT_EQ(frame.at<cv::Vec3b>(60, 80), cv::Vec3b(0, 0, 255));
    EXPECT_EQ(frame.at<cv::Vec3b>(10, 10), cv::Vec3b(255, 0, 0));
  }
}

TEST(PlaneRenderer, AFloorReachingBehindTheCameraIsClippedNotMirrored) {
  // A floor 1 m below the camera from 5 m behind to 10 m ahead: the lower half of the image, nothing above the
  // horizon (a mirrored copy of the part behind would land there).
  const TexturedPolygon floor = TexturedQuad({-4, 1, -5}, {4, 1, -5}, {4, 1, 10}, {-4, 1, 10}, Plain({0, 200, 0}));
  const cv::Mat frame = RenderPolygons({floor}, Camera());
  EXPECT_EQ(frame.at<cv::Vec3b>(119, 80), cv::Vec3b(0, 200, 0));
  EXPECT_EQ(frame.at<cv::Vec3b>(80, 80), cv::Vec3b(0, 200, 0));
  for (int y = 0; y < 60; ++y) ASSERT_EQ(frame.at<cv::Vec3b>(y, 80), cv::Vec3b(40, 40, 40)) << y;
  // Wholly behind: nothing.
  const TexturedPolygon behind = TexturedQuad({-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3}, Plain({0, 0, 255}));
  EXPECT_EQ(cv::countNonZero(RenderPolygons({behind}, Camera()).reshape(1) != 40), 0);
}

TEST(PlaneRenderer, DistantTexturesAreReadFromTheirMipLevel) {
  // A fine checkerboard far away: read at level 0 it aliases into a pattern of its own; from its mip level it
  // is the average grey it should be.
  cv::Mat board(512, 512, CV_8UC3);
  for (int y = 0; y < 512; ++y)
    for (int x = 0; x < 512; ++x)
      board.at<cv::Vec3b>(y, x) = ((x + y) % 2) ? cv::Vec3b(255, 255, 255) : cv::Vec3b(0, 0, 0);
  const TexturedPolygon quad =
      TexturedQuad({-1, -1, 20}, {1, -1, 20}, {1, 1, 20}, {-1, 1, 20}, std::make_shared<Texture>(board));
  const cv::Mat frame = RenderPolygons({quad}, Camera());
  cv::Scalar mean, stddev;
  cv::meanStdDev(frame(cv::Rect(77, 57, 6, 6)), mean, stddev);
  EXPECT_NEAR(mean[0], 127.5, 10.0);
  EXPECT_LT(stddev[0], 10.0);
}

// A mip level shows the texture where level 0 does: pyrDown centres level-k pixel a on level-0 pixel 2^k a. Mapped as
// a box filter's (2^k a + (2^k - 1) / 2), level 2 drew this edge 0.3 px off, and a wall moved as its level changed.
TEST(PlaneRenderer, AMipLevelShowsTheTextureWhereLevelZeroDoes) {
  cv::Mat image(512, 512, CV_8UC3, cv::Scalar(0, 0, 0));
  image.colRange(256, 512).setTo(cv::Scalar(255, 255, 255));
  // 512 texels across 114 px: level 2.
  const TexturedPolygon quad =
      TexturedQuad({-1, -1, 1.75}, {1, -1, 1.75}, {1, 1, 1.75}, {-1, 1, 1.75}, std::make_shared<Texture>(image));
  // Where row 60 crosses mid-grey, to a fraction of a pixel.
  const auto edge = [&](bool mipmaps) {
    RenderOptions options;
    options.mipmaps = mipmaps;
    const cv::Mat frame = RenderPolygons({quad}, Camera(), options);
    for (int x = 20; x + 1 < 140; ++x) {
      const double a = frame.at<cv::Vec3b>(60, x)[0], b = frame.at<cv::Vec3b>(60, x + 1)[0];
      if (a < 127.5 && b >= 127.5) return x + (127.5 - a) / (b - a);
    }
    return -1.0;
  };
  const double sharp = edge(false);
  ASSERT_NEAR(sharp, 79.5, 1.0);
  EXPECT_NEAR(edge(true), sharp, 0.1);
}

TEST(PlaneRenderer, ATrapezoidShowsItsWholeTextureRegion) {
  // The texture's region [16, 48] x [0, 63] stretched onto a trapezoid: its centre column lands mid-way.
  cv::Mat image(64, 64, CV_8UC3, cv::Scalar(0, 0, 255));
  image.colRange(32, 64).setTo(cv::Scalar(0, 255, 0));
  const TexturedPolygon quad = TexturedQuad({{-1, -1, 4}, {1, -1, 4}, {2, 1, 4}, {-2, 1, 4}},
                                            std::make_shared<Texture>(image), {{16, 0}, {48, 0}, {48, 63}, {16, 63}});
  const cv::Mat frame = RenderPolygons({quad}, Camera());
  EXPECT_EQ(frame.at<cv::Vec3b>(80, 70), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(frame.at<cv::Vec3b>(80, 90), cv::Vec3b(0, 255, 0));
  EXPECT_EQ(frame.at<cv::Vec3b>(60, 40), cv::Vec3b(40, 40, 40));
}

}  // namespace
}  // namespace vmap
