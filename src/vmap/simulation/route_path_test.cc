#include "vmap/simulation/route_path.h"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {

std::string ErrorOfCsv(const std::string& text, double width = 3.0) {
  testing::ScopedTempDir temp("route_csv");
  const auto path = temp.path() / "route.csv";
  std::ofstream(path) << text;
  try {
    ReadRouteCsv(path, width);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(RoutePath, ArcLengthPosesAndSignedLateralOffsets) {
  const RoutePath path({{0, 0}, {4, 0}, {4, 3}});
  EXPECT_DOUBLE_EQ(path.length(), 7.0);
  const Pose2d middle = path.At(5.0);
  EXPECT_DOUBLE_EQ(middle.x, 4.0);
  EXPECT_DOUBLE_EQ(middle.y, 1.0);
  EXPECT_NEAR(middle.yaw, M_PI / 2, 1e-12);
  const RoutePath::Projection left = path.Project({2.0, 0.3});
  EXPECT_DOUBLE_EQ(left.s, 2.0);
  EXPECT_DOUBLE_EQ(left.lateral, 0.3);  // left of the direction of travel
  EXPECT_DOUBLE_EQ(path.Project({4.5, 2.0}).lateral, -0.5);
  // A window of arc length picks the pass that is meant.
  EXPECT_DOUBLE_EQ(path.Project({3.9, 0.2}, 4.5, 7.0).s, 4.5);
}

TEST(RoutePath, BuiltInRoutesHaveTheirShapes) {
  const SimulatedRoute straight = MakeRoute(RouteShape::kStraight);
  EXPECT_DOUBLE_EQ(straight.path.length(), 10.0);
  EXPECT_DOUBLE_EQ(straight.corridor.length(), 16.0);  // 3 m beyond both ends
  EXPECT_DOUBLE_EQ(straight.path_start, 3.0);
  const SimulatedRoute turn = MakeRoute(RouteShape::kTurn);
  EXPECT_NEAR(turn.path.length(), 8.0 + 2.5 * M_PI / 2, 0.01);
  EXPECT_NEAR(turn.path.At(turn.path.length()).yaw, M_PI / 2, 1e-9);
  const SimulatedRoute s_curve = MakeRoute(RouteShape::kSCurve);
  EXPECT_NEAR(s_curve.path.At(s_curve.path.length()).yaw, 0.0, 1e-9);
  const SimulatedRoute loop = MakeRoute(RouteShape::kLoop);
  EXPECT_TRUE(loop.corridor.closed());
  EXPECT_FALSE(loop.path.closed());
  EXPECT_NEAR(loop.path.length(), 6.0 + 5.0 * M_PI - 2.0, 0.02);
  const Pose2d goal = loop.path.At(loop.path.length());
  EXPECT_NEAR(std::hypot(goal.x, goal.y), 2 * 2.5 * std::sin(0.4), 0.01);  // 2 m of arc short of the start
  for (const SimulatedRoute* route : {&straight, &turn, &s_curve, &loop}) {
    EXPECT_NO_THROW(CheckCorridor(route->corridor, 3.0, route->name)) << route->name;
  }
  EXPECT_EQ(ParseRouteShape("s-curve"), RouteShape::kSCurve);
  EXPECT_THROW(ParseRouteShape("zigzag"), InputError);
}

TEST(RoutePath, ReadsWaypointCsvs) {
  testing::ScopedTempDir temp("route_csv_ok");
  const auto path = temp.path() / "route.csv";
  std::ofstream(path) << "x,y\n# a comment\n0,0\r\n5, 0\n5,5\n";
  const SimulatedRoute route = ReadRouteCsv(path, 3.0);
  EXPECT_DOUBLE_EQ(route.path.length(), 10.0);
  EXPECT_FALSE(route.corridor.closed());
  const auto loop = temp.path() / "loop.csv";
  std::ofstream(loop) << "0,0\n8,0\n8,8\n0,8\n0,0\n";
  EXPECT_TRUE(ReadRouteCsv(loop, 3.0).corridor.closed());
  // A spreadsheet's UTF-8 byte order mark before the first waypoint: no header, the waypoint.
  const auto marked = temp.path() / "marked.csv";
  std::ofstream(marked) << "\xEF\xBB\xBF"
                           "1,0\n5,0\n";
  EXPECT_DOUBLE_EQ(ReadRouteCsv(marked, 3.0).path.length(), 4.0);
}

TEST(RoutePath, MalformedAndNonsenseCsvsAreRefusedNamingTheLine) {
  EXPECT_NE(ErrorOfCsv("0,0\n").find("at least two"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("").find("at least two"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0\n1,abc\n").find("line 2"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0\n5\n").find("line 2"), std::string::npos);
  // A third column (t,x,y or x,y,yaw) is refused, not dropped: read as x,y, t,x,y would be another route.
  // Its header line is skipped as any header is.
  EXPECT_NE(ErrorOfCsv("x,y,yaw\n0,0,0\n5,0,0\n").find("line 2: 3 values"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0\n5,0,1.57\n").find("line 2: 3 values"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0\nnan,3\n").find("finite"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0\n1e300,0\n").find("finite"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0\n0,0\n").find("within 1 mm of the one before"), std::string::npos);
  // A binary line is quoted with escapes, not sent to the terminal as it is.
  const std::string binary = ErrorOfCsv("0,0\n\x01\x1b[2J,\x7f\n");
  EXPECT_NE(binary.find("line 2: \"\\x01\\x1b[2J,\\x7f\""), std::string::npos) << binary;
  // Folding back on itself: a hairpin narrower than the corridor, a crossing.
  EXPECT_NE(ErrorOfCsv("0,0\n10,0\n0,0.5\n").find("too sharply"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0\n10,0\n10,10\n5,10\n5,-10\n").find("within"), std::string::npos);
  // A turn a wide corridor cannot make.
  EXPECT_NE(ErrorOfCsv("0,0\n2,0\n2,2\n", 8.0).find("too sharply"), std::string::npos);
  EXPECT_NE(ErrorOfCsv("0,0\n3000,0\n").find("2 km"), std::string::npos);
}

}  // namespace
}  // namespace vmap
