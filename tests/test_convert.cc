// The API's messages to the engine's types: a good spec becomes the body it describes, and every
// bad field is refused with its own name.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "convert.h"

namespace tumble::server {
namespace {

v1::BodySpec unit_box() {
  v1::BodySpec spec;
  v1::Vec3* size = spec.mutable_shape()->mutable_box()->mutable_size();
  size->set_x(1);
  size->set_y(2);
  size->set_z(3);
  spec.mutable_position()->set_z(5);
  spec.set_mass(2);
  return spec;
}

TEST(Convert, AGoodSpecBecomesItsBody) {
  v1::BodySpec spec = unit_box();
  spec.mutable_orientation()->set_w(1.0005);  // nearly unit: normalised
  spec.set_friction(0.3);
  const Result<BodyDef> def = body_from_proto(spec);
  ASSERT_TRUE(def.ok()) << def.error();
  EXPECT_EQ(std::get<BoxDef>(def.value().shape).half_extents, Vec3(0.5, 1, 1.5));
  EXPECT_EQ(def.value().position, Vec3(0, 0, 5));
  EXPECT_EQ(def.value().mass, 2);
  EXPECT_EQ(def.value().friction, 0.3);
  EXPECT_NEAR(def.value().orientation.norm(), 1, 1e-15);
}

TEST(Convert, EveryBadFieldIsNamed) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    std::function<void(v1::BodySpec&)> spoil;
    const char* field;
  };
  const Case cases[] = {
      {[](v1::BodySpec& s) { s.clear_shape(); }, "shape:"},
      {[](v1::BodySpec& s) { s.mutable_shape()->mutable_box()->mutable_size()->set_y(0); },
       "shape.box.size.y:"},
      {[](v1::BodySpec& s) { s.mutable_shape()->mutable_sphere()->set_radius(-1); },
       "shape.sphere.radius:"},
      {[](v1::BodySpec& s) { s.mutable_shape()->mutable_capsule()->set_radius(1); },
       "shape.capsule.half_height:"},
      {[](v1::BodySpec& s) { s.mutable_shape()->mutable_hull()->add_points(1); },
       "shape.hull.points:"},
      {[&](v1::BodySpec& s) { s.mutable_position()->set_y(nan); }, "position.y:"},
      {[](v1::BodySpec& s) { s.mutable_linear_velocity()->set_z(INFINITY); }, "linear_velocity.z:"},
      {[](v1::BodySpec& s) { s.mutable_orientation(); }, "orientation:"},  // the zero quaternion
      {[](v1::BodySpec& s) { s.mutable_orientation()->set_w(2); }, "orientation:"},
      {[](v1::BodySpec& s) { s.set_mass(-1); }, "mass:"},
      {[](v1::BodySpec& s) { s.set_density(0); }, "density:"},
      {[](v1::BodySpec& s) { s.set_friction(-0.1); }, "friction:"},
      {[](v1::BodySpec& s) { s.set_restitution(1.5); }, "restitution:"},
      {[](v1::BodySpec& s) { s.mutable_shape()->mutable_plane(); }, "type:"},
      {[](v1::BodySpec& s) { s.set_type(static_cast<v1::BodyType>(7)); }, "type:"},
  };
  for (const Case& c : cases) {
    v1::BodySpec spec = unit_box();
    c.spoil(spec);
    const Result<BodyDef> def = body_from_proto(spec);
    ASSERT_FALSE(def.ok()) << c.field;
    EXPECT_EQ(def.error().rfind(c.field, 0), 0u) << def.error();
  }
}

TEST(Convert, FrameKeepsOnlyWhatTheSubscriberAskedFor) {
  FrameData frame;
  frame.step = 7;
  for (std::uint64_t id : {1, 2, 3}) {
    frame.ids.push_back(id);
    for (int k = 0; k < 3; ++k) {
      frame.positions.push_back(10.0 * id + k);
      frame.linear_velocities.push_back(1);
      frame.angular_velocities.push_back(2);
    }
    for (int k = 0; k < 4; ++k)
      frame.orientations.push_back(k == 0 ? 1 : 0);
  }
  v1::Frame all;
  frame_to_proto(frame, {}, &all);
  EXPECT_EQ(all.ids_size(), 3);
  EXPECT_EQ(all.linear_velocities_size(), 0);
  EXPECT_FALSE(all.has_stats());
  v1::Frame some;
  FrameOptions options;
  options.velocities = true;
  options.ids = {2};
  frame_to_proto(frame, options, &some);
  ASSERT_EQ(some.ids_size(), 1);
  EXPECT_EQ(some.ids(0), 2u);
  EXPECT_EQ(some.positions(0), 20);
  EXPECT_EQ(some.linear_velocities_size(), 3);
  EXPECT_EQ(some.step(), 7u);
}

}  // namespace
}  // namespace tumble::server
