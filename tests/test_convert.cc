// The API's messages to the engine's types: a good spec becomes the body it describes, and every
// bad field is refused with its own name.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

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

// The engine's names for a shape's fields (its ShapeDef's) in the API's terms (the v1 messages').
TEST(Convert, EngineRefusalsAreNamedInTheApisTerms) {
  v1::Shape compound;
  compound.mutable_compound()->add_parts()->mutable_shape()->mutable_sphere()->set_radius(1);
  compound.mutable_compound()->add_parts()->mutable_shape()->mutable_hull()->add_points(0);
  EXPECT_EQ(in_api_terms("shape.parts[1].shape.points: coplanar", compound),
            "shape.compound.parts[1].shape.hull.points: coplanar");
  EXPECT_EQ(in_api_terms("shape.parts[0].shape.radius: below min_size", compound),
            "shape.compound.parts[0].shape.sphere.radius: below min_size");
  EXPECT_EQ(in_api_terms("shape.parts[0].pose.orientation: must be unit", compound),
            "shape.compound.parts[0].pose.orientation: must be unit");
  // A part that is not in the message (no such index): the compound's name alone.
  EXPECT_EQ(in_api_terms("shape.parts[7].shape.points: x", compound),
            "shape.compound.parts[7].shape.points: x");
  v1::Shape box;
  box.mutable_box();
  EXPECT_EQ(in_api_terms("shape.half_extents: below min_size", box),
            "shape.half_extents: below min_size");
  EXPECT_EQ(in_api_terms("mass: must be > 0", box), "mass: must be > 0");
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

// Every field of the message carries the engine's counter of the same name: each counter gets its
// own value, and every field, found by name, must hold it (a field added to the message without
// its conversion stays 0 and fails).
TEST(Convert, StepStatsCarryEveryCounter) {
  StepStats s;
  std::vector<std::pair<std::string, double>> expected;
  double next = 1;
  const auto set = [&](const char* name, auto& field) {
    field = static_cast<std::remove_reference_t<decltype(field)>>(next);
    expected.emplace_back(name, next);
    next += 1;
  };
  set("step", s.step);
  set("pairs", s.pairs);
  set("manifolds", s.manifolds);
  set("contact_points", s.contact_points);
  set("islands", s.islands);
  set("exact_islands", s.exact_islands);
  set("iterative_islands", s.iterative_islands);
  set("coloured_islands", s.coloured_islands);
  set("colours", s.colours);
  set("overflow_manifolds", s.overflow_manifolds);
  set("coloured_islands_alone", s.coloured_islands_alone);
  set("packed_manifolds", s.packed_manifolds);
  set("reused_manifolds", s.reused_manifolds);
  set("exact_fallbacks", s.exact_fallbacks);
  set("exact_oversized", s.exact_oversized);
  set("lemke_pivots", s.lemke_pivots);
  set("stiffened_islands", s.stiffened_islands);
  set("stiffness_capped", s.stiffness_capped);
  set("velocity_iterations", s.velocity_iterations);
  set("residual", s.residual);
  set("sleeping_bodies", s.sleeping_bodies);
  set("solved_joints", s.solved_joints);
  set("joint_error", s.joint_error);
  set("woken_bodies", s.woken_bodies);
  set("solver_bodies", s.solver_bodies);
  set("swept_bodies", s.swept_bodies);
  set("continuous_impacts", s.continuous_impacts);
  set("continuous_limit_hits", s.continuous_limit_hits);
  set("max_penetration", s.max_penetration);
  set("gyroscopic_limit_hits", s.gyroscopic_limit_hits);
  set("pair_limit_hits", s.pair_limit_hits);
  set("impact_limit_hits", s.impact_limit_hits);
  set("resting_contact_points", s.resting_contact_points);
  set("non_finite_bodies", s.non_finite_bodies);
  set("slowed_bodies", s.slowed_bodies);
  set("bodies_at_edge", s.bodies_at_edge);
  set("broad_phase_seconds", s.time.broad_phase);
  set("narrow_phase_seconds", s.time.narrow_phase);
  set("prepare_seconds", s.time.prepare);
  set("solve_seconds", s.time.solve);
  set("correct_positions_seconds", s.time.correct_positions);
  set("continuous_seconds", s.time.continuous);
  set("total_seconds", s.time.total);

  v1::StepStats out;
  stats_to_proto(s, &out);
  const google::protobuf::Descriptor* descriptor = out.GetDescriptor();
  const google::protobuf::Reflection* reflection = out.GetReflection();
  EXPECT_EQ(descriptor->field_count(), static_cast<int>(expected.size()))
      << "a field of tumble.v1.StepStats that no engine counter is expected in";
  for (const auto& [name, value] : expected) {
    const google::protobuf::FieldDescriptor* field = descriptor->FindFieldByName(name);
    ASSERT_NE(field, nullptr) << name << ": not in tumble.v1.StepStats";
    double got = -1;
    switch (field->cpp_type()) {
      case google::protobuf::FieldDescriptor::CPPTYPE_UINT32:
        got = reflection->GetUInt32(out, field);
        break;
      case google::protobuf::FieldDescriptor::CPPTYPE_UINT64:
        got = static_cast<double>(reflection->GetUInt64(out, field));
        break;
      case google::protobuf::FieldDescriptor::CPPTYPE_DOUBLE:
        got = reflection->GetDouble(out, field);
        break;
      default:
        ADD_FAILURE() << name << ": an unexpected type";
    }
    EXPECT_EQ(got, value) << name;
  }
}

}  // namespace
}  // namespace tumble::server
