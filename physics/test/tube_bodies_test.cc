#include "physics/tube_bodies.h"

#include <algorithm>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick::physics {
namespace {

using ::testing::HasSubstr;
constexpr double kR = 0.0125;
constexpr double kTol = 1e-9;

Cylinder MakeCylinder(const Eigen::Vector3d& start, const Eigen::Vector3d& end, double radius = kR) {
  Cylinder c;
  c.start = start;
  c.end = end;
  c.radius = radius;
  return c;
}

TEST(TubeSegments, SingleCylinderHasFlatEnds) {
  Tube tube;
  tube.cylinders = {MakeCylinder({0, 0, 0}, {0.3, 0, 0})};
  const std::vector<TubeSegment> segments = MakeTubeSegments(tube, 0.001);
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_EQ(segments[0].b, Eigen::Vector3d(0.3, 0, 0));
  EXPECT_FALSE(segments[0].sphere_a);
  EXPECT_FALSE(segments[0].sphere_b);
}

TEST(TubeSegments, JointLongerThanMinimumGetsAJointSegmentAndSpheres) {
  Tube tube;
  tube.cylinders = {MakeCylinder({0, 0, 0}, {0.2, 0, 0}, 0.01),
                    MakeCylinder({0.25, 0, 0}, {0.45, 0.1, 0}, 0.02)};
  const std::vector<TubeSegment> segments = MakeTubeSegments(tube, 0.001);
  ASSERT_EQ(segments.size(), 3u);
  // The modeled cylinders: spheres on the endpoints involved in the joint, free ends flat.
  EXPECT_FALSE(segments[0].sphere_a);
  EXPECT_TRUE(segments[0].sphere_b);
  EXPECT_TRUE(segments[1].sphere_a);
  EXPECT_FALSE(segments[1].sphere_b);
  EXPECT_EQ(segments[1].radius, 0.02);
  // The joint links cylinders[0].end to cylinders[1].start with the mean radius.
  EXPECT_TRUE(segments[2].joint);
  EXPECT_EQ(segments[2].a, tube.cylinders[0].end);
  EXPECT_EQ(segments[2].b, tube.cylinders[1].start);
  EXPECT_NEAR(segments[2].radius, 0.015, kTol);
}

TEST(TubeSegments, ShortJointGetsSpheresOnly) {
  Tube tube;
  tube.cylinders = {MakeCylinder({0, 0, 0}, {0.2, 0, 0}), MakeCylinder({0.2005, 0, 0}, {0.4, 0.1, 0}),
                    MakeCylinder({0.4, 0.1, 0}, {0.5, 0.3, 0})};
  const std::vector<TubeSegment> segments = MakeTubeSegments(tube, 0.001);
  ASSERT_EQ(segments.size(), 3u);
  EXPECT_TRUE(segments[1].sphere_a);
  EXPECT_TRUE(segments[1].sphere_b);
  for (const TubeSegment& s : segments) EXPECT_FALSE(s.joint);
}

TEST(TubeSegments, InvalidTubesAreNamed) {
  Tube empty;
  empty.id = 7;
  EXPECT_THAT([&] { MakeTubeSegments(empty, 0.001); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("tube 7 has no cylinders")));
  Tube thin;
  thin.id = 3;
  thin.cylinders = {MakeCylinder({0, 0, 0}, {0.2, 0, 0}), MakeCylinder({0.2, 0, 0}, {0.4, 0, 0}, 0.0)};
  EXPECT_THAT([&] { MakeTubeSegments(thin, 0.001); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("tube 3, cylinder 1: radius")));
  Tube point;
  point.cylinders = {MakeCylinder({0.1, 0, 0}, {0.1, 0, 0})};
  EXPECT_THAT([&] { MakeTubeSegments(point, 0.001); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("cylinder 0: length = 0")));
  Tube nan;
  nan.cylinders = {MakeCylinder({0, 0, 0}, {std::nan(""), 0, 0})};
  EXPECT_THAT([&] { MakeTubeSegments(nan, 0.001); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("non-finite endpoint")));
}

/// Counts the compound's children of a Bullet shape type.
int CountChildren(const TubeShape& shape, int type) {
  int count = 0;
  for (int i = 0; i < shape.compound->getNumChildShapes(); ++i) {
    count += shape.compound->getChildShape(i)->getShapeType() == type;
  }
  return count;
}

TEST(TubeShape, CapsulesWhereCylindersCarrySpheresFlatPiecesAtFreeEnds) {
  Tube tube;  // three cylinders, one joint with a 5 cm gap
  tube.cylinders = {MakeCylinder({0, 0, 0}, {0.1, 0, 0}), MakeCylinder({0.1, 0, 0}, {0.2, 0.05, 0}),
                    MakeCylinder({0.25, 0.05, 0}, {0.35, 0.1, 0})};
  const TubeShape shape = MakeTubeShape(MakeTubeSegments(tube, 0.001), 0.055, 0.001);
  ASSERT_NE(shape.compound, nullptr);
  // Middle cylinder and joint: capsules; each end cylinder: a capsule plus a flat piece.
  EXPECT_EQ(CountChildren(shape, CAPSULE_SHAPE_PROXYTYPE), 4);
  EXPECT_EQ(CountChildren(shape, CYLINDER_SHAPE_PROXYTYPE), 2);
  EXPECT_EQ(shape.compound->getNumChildShapes(), 6);
  // A one-cylinder tube is a plain cylinder.
  Tube straight;
  straight.cylinders = {MakeCylinder({0, 0, 0}, {0.3, 0, 0})};
  const TubeShape single = MakeTubeShape(MakeTubeSegments(straight, 0.001), 0.055, 0.001);
  EXPECT_EQ(single.compound->getNumChildShapes(), 1);
  EXPECT_EQ(CountChildren(single, CYLINDER_SHAPE_PROXYTYPE), 1);
}

TEST(TubeShape, ExtentMatchesTheThesisModel) {
  // A straight two-cylinder tube along x: its compound must span exactly [start, end] along x
  // (flat free ends, no capsule cap beyond them) and ±R across.
  Tube tube;
  tube.cylinders = {MakeCylinder({0.1, 0.2, 0.3}, {0.3, 0.2, 0.3}),
                    MakeCylinder({0.3, 0.2, 0.3}, {0.5, 0.2, 0.3})};
  const TubeShape shape = MakeTubeShape(MakeTubeSegments(tube, 0.001), 0.055, 0.001);
  btVector3 lo, hi;
  shape.compound->getAabb(ToBt(shape.X_TubeC), lo, hi);
  constexpr double kAabbTol = 0.0011;  // Bullet pads AABBs by the collision margin
  EXPECT_NEAR(lo.x(), 0.1, kAabbTol);
  EXPECT_NEAR(hi.x(), 0.5, kAabbTol);
  EXPECT_NEAR(lo.z(), 0.3 - kR, kAabbTol);
  EXPECT_NEAR(hi.z(), 0.3 + kR, kAabbTol);
}

TEST(TubeShape, CentreOfMassAndPrincipalAxesOfAStraightTube) {
  Tube tube;
  tube.cylinders = {MakeCylinder({0.1, 0.2, 0.3}, {0.3, 0.2, 0.3}),
                    MakeCylinder({0.3, 0.2, 0.3}, {0.5, 0.2, 0.3})};
  const TubeShape shape = MakeTubeShape(MakeTubeSegments(tube, 0.001), 0.055, 0.001);
  EXPECT_TRUE(shape.X_TubeC.translation().isApprox(Eigen::Vector3d(0.3, 0.2, 0.3), 1e-9));
  // The long axis carries the smallest moment; the two others are equal.
  const btVector3& I = shape.inertia;
  const double smallest = std::min({I.x(), I.y(), I.z()}), largest = std::max({I.x(), I.y(), I.z()});
  EXPECT_LT(smallest, 0.01 * largest);
  EXPECT_NEAR(largest, 0.055 * 0.4 * 0.4 / 12.0, 0.1 * largest);  // thin rod, mL²/12
  EXPECT_NEAR(shape.reach, 0.2 + kR, kTol);
  EXPECT_EQ(shape.radius, kR);
}

TEST(TubeShape, SameTubeSameShapeBitwise) {
  Tube tube;
  tube.cylinders = {MakeCylinder({0, 0, 0}, {0.2, 0.01, 0}), MakeCylinder({0.21, 0.02, 0}, {0.3, 0.2, 0.05})};
  const std::vector<TubeSegment> segments = MakeTubeSegments(tube, 0.001);
  const TubeShape a = MakeTubeShape(segments, 0.055, 0.001), b = MakeTubeShape(segments, 0.055, 0.001);
  EXPECT_EQ(a.X_TubeC.matrix(), b.X_TubeC.matrix());
  EXPECT_EQ(a.inertia, b.inertia);
}

TEST(BulletWorld, KinematicBodyMovesWithTheVelocityOfItsPoses) {
  BulletWorld world;
  btSphereShape sphere(0.01);
  btRigidBody* body = world.AddBody(btRigidBody::btRigidBodyConstructionInfo(0.0, nullptr, &sphere), true);
  EXPECT_TRUE(body->isKinematicObject());
  EXPECT_FALSE(body->isStaticObject());
  constexpr double kDt = 0.01, kSpeed = 0.1;
  for (int step = 1; step <= 3; ++step) {
    body->setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, 0, kSpeed * kDt * step)));
    world.world->stepSimulation(kDt, 0);
    EXPECT_NEAR(body->getLinearVelocity().z(), kSpeed, 1e-9);
    EXPECT_NE(body->getActivationState(), ISLAND_SLEEPING);
  }
  world.world->removeRigidBody(body);
}

TEST(BulletWorld, BinHasAFloorPlaneAndFourWalls) {
  BulletWorld world;
  AddBinBodies(world, BinConfig{}, 0.05, 0.7, 0.5, 0.001);
  ASSERT_EQ(world.bodies.size(), 5u);
  EXPECT_EQ(world.bodies[0]->getCollisionShape()->getShapeType(), STATIC_PLANE_PROXYTYPE);
  btVector3 lo, hi;  // +x wall: inner face at x = 0.4, 5 cm thick, 20 cm tall
  world.bodies[1]->getCollisionShape()->getAabb(world.bodies[1]->getWorldTransform(), lo, hi);
  constexpr double kMarginTol = 0.0011;
  EXPECT_NEAR(lo.x(), 0.4, kMarginTol);
  EXPECT_NEAR(hi.x(), 0.45, kMarginTol);
  EXPECT_NEAR(hi.z(), 0.2, kMarginTol);
}

}  // namespace
}  // namespace tubepick::physics
