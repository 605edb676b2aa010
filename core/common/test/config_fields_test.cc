#include "core/common/config_fields.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/common/errors.h"

namespace tubepick {
namespace config_fields_test {

using std::chrono::milliseconds;
using ::testing::HasSubstr;

enum class Colour { kRed, kGreen };

std::string ColourName(Colour c) { return c == Colour::kRed ? "red" : "green"; }

Colour ParseColour(const std::string& text, const std::string& path) {
  if (text == "red") return Colour::kRed;
  if (text == "green") return Colour::kGreen;
  throw InvalidArgument(path + ": unknown colour '" + text + "'");
}

struct Inner {
  double width = 0.5;
  Eigen::Vector3d size{1.0, 2.0, 3.0};
};

struct Circle {
  double radius = 1.0;
};
struct Square {
  double side = 2.0;
  std::uint32_t count = 3;
};
using Shape = std::variant<Circle, Square>;

std::string ShapeName(const Shape& s) { return std::holds_alternative<Circle>(s) ? "circle" : "square"; }

Shape MakeShape(const std::string& name, const std::string& path) {
  if (name == "circle") return Circle{};
  if (name == "square") return Square{};
  throw InvalidArgument(path + ": unknown shape '" + name + "'");
}

const VariantListSpec<Shape> kShapes{"shapes", "- circle: {radius: 1}", ShapeName, MakeShape};

struct Everything {
  double ratio = 0.1;
  bool flag = true;
  int offset = -4;
  std::uint32_t count = 7;
  std::uint64_t seed = 123456789012345ULL;
  std::string name = "plain";
  std::string address = "0.0.0.0:50051";
  Eigen::Vector2d xy{0.25, -1.5};
  Colour colour = Colour::kGreen;
  milliseconds timeout{2'500};
  double angle = M_PI / 3.0;
  Eigen::Isometry3d X_AB = Eigen::Isometry3d(Eigen::Translation3d(0.1, 0.2, 0.3));
  std::optional<Eigen::Isometry3d> X_AC;
  Inner inner;
  std::optional<Inner> maybe;
  std::vector<Shape> shapes{Circle{}, Square{}};
};

template <typename Visit>
void DescribeFields(Visit& v, Inner& p) {
  v("width", p.width, "metres");
  v("size", p.size);
}

template <typename Visit>
void DescribeFields(Visit& v, Circle& p) {
  v("radius", p.radius);
}

template <typename Visit>
void DescribeFields(Visit& v, Square& p) {
  v("side", p.side);
  v("count", p.count);
}

template <typename Visit>
void DescribeFields(Visit& v, Everything& p) {
  v.Heading("scalars");
  v("ratio", p.ratio, "a fraction\nin [0, 1]");
  v("flag", p.flag);
  v("offset", p.offset);
  v("count", p.count);
  v("seed", p.seed);
  v("name", p.name);
  v("address", p.address);
  v("xy", p.xy);
  v.Enum("colour", p.colour, ColourName, ParseColour, "red or green");
  v.Seconds("timeout", p.timeout);
  v.Degrees("angle_deg", p.angle);
  v.Pose("X_AB", p.X_AB);
  v.OptionalPose("X_AC", p.X_AC);
  v.Section("inner", p.inner, "a nested section");
  v.OptionalSection("maybe", p.maybe);
  v.VariantList("shapes", p.shapes, kShapes);
}

Everything Parse(const std::string& yaml) {
  Everything e;
  ParseFields(yaml, "test", e);
  return e;
}

std::string ErrorOf(const std::string& yaml) {
  try {
    Parse(yaml);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

void ExpectSame(const Everything& a, const Everything& b) {
  EXPECT_EQ(a.ratio, b.ratio);
  EXPECT_EQ(a.flag, b.flag);
  EXPECT_EQ(a.offset, b.offset);
  EXPECT_EQ(a.count, b.count);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.address, b.address);
  EXPECT_EQ(a.xy, b.xy);
  EXPECT_EQ(a.colour, b.colour);
  EXPECT_EQ(a.timeout, b.timeout);
  EXPECT_NEAR(a.angle, b.angle, 1e-15);
  EXPECT_TRUE(a.X_AB.isApprox(b.X_AB, 1e-12));
  ASSERT_EQ(a.X_AC.has_value(), b.X_AC.has_value());
  if (a.X_AC) {
    EXPECT_TRUE(a.X_AC->isApprox(*b.X_AC, 1e-12));
  }
  EXPECT_EQ(a.inner.width, b.inner.width);
  EXPECT_EQ(a.inner.size, b.inner.size);
  ASSERT_EQ(a.maybe.has_value(), b.maybe.has_value());
  if (a.maybe) {
    EXPECT_EQ(a.maybe->width, b.maybe->width);
  }
  ASSERT_EQ(a.shapes.size(), b.shapes.size());
  for (std::size_t i = 0; i < a.shapes.size(); ++i) EXPECT_EQ(ShapeName(a.shapes[i]), ShapeName(b.shapes[i]));
}

TEST(ConfigFields, EmptyDocumentKeepsEveryValue) { ExpectSame(Parse(""), Everything{}); }

TEST(ConfigFields, DumpOfTheDefaultsReadsBack) {
  const std::string yaml = DumpFields(Everything{}, "header line 1\nheader line 2");
  ExpectSame(Parse(yaml), Everything{});
  EXPECT_THAT(yaml, HasSubstr("# header line 1\n# header line 2\n\n# scalars\n"));
  EXPECT_THAT(yaml, HasSubstr("# a fraction\n# in [0, 1]\nratio: 0.1\n"));
  EXPECT_THAT(yaml, HasSubstr("address: \"0.0.0.0:50051\"\n"));
  EXPECT_THAT(yaml, HasSubstr("name: plain\n"));
  EXPECT_THAT(yaml, HasSubstr("timeout: 2.5\n"));
  EXPECT_THAT(yaml, HasSubstr("X_AC: null\n"));
  EXPECT_THAT(yaml, HasSubstr("maybe: null\n"));
  EXPECT_THAT(yaml,
              HasSubstr("\ninner:  # a nested section\n  width: 0.5  # metres\n  size: [1.0, 2.0, 3.0]\n"));
  EXPECT_THAT(yaml, HasSubstr("shapes:\n  - circle:\n      radius: 1.0\n  - square:\n"));
}

TEST(ConfigFields, DumpOfChangedValuesReadsBackExactly) {
  Everything e;
  e.ratio = 1.0 / 3.0;
  e.flag = false;
  e.offset = 12;
  e.count = 0;
  e.seed = 9223372036854775807ULL;  // the largest the reader takes (it reads via long long)
  e.name = "off";                   // a YAML 1.1 boolean word: quoted
  e.address = "say \"hi\"\\\n";
  e.xy = Eigen::Vector2d(1e-30, 3e20);
  e.colour = Colour::kRed;
  e.timeout = milliseconds(1);
  e.angle = 0.7;
  e.X_AB.linear() = Eigen::AngleAxisd(2.5, Eigen::Vector3d(1.0, 0.2, -0.3).normalized()).toRotationMatrix();
  e.X_AC = Eigen::Isometry3d(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  e.inner.size = Eigen::Vector3d(-0.0, 7.0, 0.1 + 0.2);
  e.maybe = Inner{0.75, Eigen::Vector3d::Ones()};
  e.shapes = {Square{5.0, 9}};
  const std::string yaml = DumpFields(e);
  const Everything back = Parse(yaml);
  ExpectSame(back, e);
  EXPECT_EQ(std::get<Square>(back.shapes[0]).count, 9u);
  ExpectSame(Parse(DumpFields(back)), e);  // stable (poses to round-off)
  EXPECT_THAT(yaml, HasSubstr("name: \"off\"\n"));
  // A half turn's round-off (w ~ 6e-17) is written as 0.
  EXPECT_THAT(yaml, HasSubstr("orientation_xyzw: [1.0, 0.0, 0.0, 0.0]"));
  e.shapes.clear();
  EXPECT_TRUE(Parse(DumpFields(e)).shapes.empty());
}

TEST(ConfigFields, UnknownKeysNameTheirPath) {
  EXPECT_THAT(ErrorOf("ratioo: 1"), HasSubstr("unknown key(s): ratioo"));
  EXPECT_THAT(ErrorOf("inner: {width: 1, height: 2}"), HasSubstr("unknown key(s): inner.height"));
  EXPECT_THAT(ErrorOf("maybe: {depth: 2}"), HasSubstr("unknown key(s): maybe.depth"));
  EXPECT_THAT(ErrorOf("X_AB: {frame: a}"), HasSubstr("unknown key(s): X_AB.frame"));
  EXPECT_THAT(ErrorOf("shapes: [{square: {sides: 4}}]"), HasSubstr("unknown key(s): shapes[0].square.sides"));
}

TEST(ConfigFields, KeysThatAreNotNamesAreErrorsNamingTheirPath) {
  EXPECT_THAT(ErrorOf("[ratio]: 1"), HasSubstr("document: a key must be a name, got a list (line 1)"));
  EXPECT_THAT(ErrorOf("inner:\n  ? {width: 1}\n  : 2\n"),
              HasSubstr("inner: a key must be a name, got a mapping (line 2)"));
  EXPECT_THAT(ErrorOf("shapes: [{square: {? [4] : 1}}]"),
              HasSubstr("shapes[0].square: a key must be a name"));
}

TEST(ConfigFields, WrongTypesNameTheirPath) {
  EXPECT_THAT(ErrorOf("ratio: much"), HasSubstr("ratio: expected a number, got 'much'"));
  EXPECT_THAT(ErrorOf("offset: 1.5"), HasSubstr("offset: expected an integer"));
  EXPECT_THAT(ErrorOf("offset: 3000000000"), HasSubstr("offset: 3000000000 is out of range"));
  EXPECT_THAT(ErrorOf("inner: 3"), HasSubstr("inner: expected a mapping"));
  EXPECT_THAT(ErrorOf("inner: {size: [1, 2]}"), HasSubstr("inner.size: expected a list of 3 numbers"));
  EXPECT_THAT(ErrorOf("colour: blue"), HasSubstr("colour: unknown colour 'blue'"));
  EXPECT_THAT(ErrorOf("timeout: 2e9"), HasSubstr("timeout: 2000000000 s is out of range"));
  EXPECT_THAT(ErrorOf("X_AC: {position: [0, 0, 1]}"), HasSubstr("X_AC: needs position and orientation_xyzw"));
  EXPECT_THAT(ErrorOf("X_AB: {orientation_xyzw: [1, 1, 0, 0]}"),
              HasSubstr("X_AB.orientation_xyzw: quaternion must be unit length"));
  EXPECT_THAT(ErrorOf("shapes: {circle: {}}"), HasSubstr("shapes: expected a list of shapes"));
  EXPECT_THAT(ErrorOf("shapes: [circle]"), HasSubstr("shapes[0]: expected a one-key mapping such as"));
  EXPECT_THAT(ErrorOf("shapes: [{hexagon: {}}]"), HasSubstr("shapes[0]: unknown shape 'hexagon'"));
}

TEST(ConfigFields, PartialInputOverridesOnlyItsKeys) {
  const Everything e = Parse(
      "angle_deg: 90\ntimeout: 0.25\nX_AB: {position: [1, 2, 3]}\nmaybe: {width: 2}\n"
      "X_AC: {position: [0, 0, 1], orientation_xyzw: [0, 0, 0, 1]}\nshapes: []\n");
  EXPECT_NEAR(e.angle, M_PI / 2.0, 1e-15);
  EXPECT_EQ(e.timeout, milliseconds(250));
  EXPECT_EQ(e.X_AB.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(e.X_AB.linear().isIdentity(1e-15));
  ASSERT_TRUE(e.maybe.has_value());
  EXPECT_EQ(e.maybe->width, 2.0);
  EXPECT_EQ(e.maybe->size, Inner{}.size);
  ASSERT_TRUE(e.X_AC.has_value());
  EXPECT_EQ(e.X_AC->translation(), Eigen::Vector3d(0, 0, 1));
  EXPECT_TRUE(e.shapes.empty());
  EXPECT_EQ(e.ratio, Everything{}.ratio);
}

// A config path that names a device or a huge file is an error, not a read without end.
TEST(ReadTextFile, RefusesMoreThanAConfigsWorth) {
  try {
    (void)ReadTextFile("/dev/zero");
    ADD_FAILURE() << "read /dev/zero";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("'/dev/zero' is larger than 16 MiB"));
  }
}

}  // namespace config_fields_test
}  // namespace tubepick
