#include "vmap/simulation/corridor_world.h"

#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/simulation/robot.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {

TEST(CorridorWorld, TheCameraSeesWallsLeftAndRightAndTheFloorBelow) {
  const SimulatedRoute route = MakeRoute(RouteShape::kStraight);
  // One plain colour per image: red, green, blue dealt to the left wall, the right wall and the floor.
  std::vector<cv::Mat> images = {cv::Mat(100, 100, CV_8UC3, cv::Scalar(0, 0, 255)),
                                 cv::Mat(100, 100, CV_8UC3, cv::Scalar(0, 255, 0)),
                                 cv::Mat(100, 100, CV_8UC3, cv::Scalar(255, 0, 0))};
  const CorridorWorld world(route.corridor, CorridorOptions{}, images);
  CameraRigOptions camera;
  const cv::Mat frame = RenderPolygons(world.polygons(), CameraView(camera, route.path.At(2.0)));
  EXPECT_EQ(frame.at<cv::Vec3b>(240, 5), cv::Vec3b(0, 0, 255));    // left: the left wall
  EXPECT_EQ(frame.at<cv::Vec3b>(240, 634), cv::Vec3b(0, 255, 0));  // right: the right wall
  EXPECT_EQ(frame.at<cv::Vec3b>(470, 320), cv::Vec3b(255, 0, 0));  // below: the floor
  // The same panels in another season: image i replaced by image i of the other list.
  const std::vector<cv::Mat> other = {images[2], images[0], images[1]};
  const cv::Mat winter = RenderPolygons(world.WithImages(other).polygons(), CameraView(camera, route.path.At(2.0)));
  EXPECT_EQ(winter.at<cv::Vec3b>(240, 5), cv::Vec3b(255, 0, 0));
  EXPECT_THROW(world.WithImages({images[0]}), InputError);
}

TEST(CorridorWorld, TextureFoldersAreReadInNaturalOrderAndOnlyImagesAccepted) {
  testing::ScopedTempDir temp("textures");
  cv::imwrite((temp.path() / "img10.png").string(), cv::Mat(20, 30, CV_8UC3, cv::Scalar(10, 10, 10)));
  cv::imwrite((temp.path() / "img2.png").string(), cv::Mat(20, 40, CV_8UC3, cv::Scalar(20, 20, 20)));
  std::ofstream(temp.path() / ".hidden") << "ignored";
  const std::vector<cv::Mat> images = ReadTextureFolder(temp.path(), "teach_textures");
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[0].cols, 40);  // img2 first
  std::ofstream(temp.path() / "notes.txt") << "not an image";
  try {
    ReadTextureFolder(temp.path(), "teach_textures");
    FAIL() << "a text file was taken for a texture";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.path(), "teach_textures");  // each front end names the option its way
    EXPECT_NE(e.problem().find("'notes.txt' cannot be decoded"), std::string::npos) << e.what();
  }
  testing::ScopedTempDir empty("textures_empty");
  EXPECT_THROW(ReadTextureFolder(empty.path(), "teach_textures"), InputError);
  EXPECT_THROW(ReadTextureFolder(empty.path() / "missing", "teach_textures"), InputError);
}

}  // namespace
}  // namespace vmap
