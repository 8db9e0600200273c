#include "physics/limits.h"

#include "body_state.h"
#include "physics/compound.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace tumble {
namespace {

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}

Status above(const std::string& field, double value, const char* unit, const char* limit,
             double bound) {
  return Status::error(field + ": " + number(value) + " " + unit + " is above limits." + limit +
                       " (" + number(bound) + " " + unit + ")");
}

Status below(const std::string& field, double value, const char* unit, const char* limit,
             double bound) {
  return Status::error(field + ": " + number(value) + " " + unit + " is below limits." + limit +
                       " (" + number(bound) + " " + unit + ")");
}

// The field that sets a shape's smallest dimension, its value, and its largest dimension.
struct ShapeSpan {
  std::string smallest_field;
  double smallest;
  std::string largest_field;
};

ShapeSpan span_of(const Shape& shape) {
  switch (shape.type()) {
    case ShapeType::kSphere:
      return {"shape.radius", shape.radius(), "shape.radius"};
    case ShapeType::kCapsule:
      return {"shape.radius", shape.radius(), "shape.half_height"};
    case ShapeType::kBox:
      return {"shape.half_extents", shape.half_extents().minCoeff(), "shape.half_extents"};
    case ShapeType::kHull:
      return {"shape.points", shape.local_bounds().extent().minCoeff() / 2, "shape.points"};
    case ShapeType::kHeightField: {
      const HeightFieldDef& def = shape.height_field()->def();
      return {"shape.spacing", std::min(def.spacing_x, def.spacing_y), "shape.heights"};
    }
    case ShapeType::kMesh:
      return {"shape.triangles", shape.mesh()->feature_size(), "shape.vertices"};
    case ShapeType::kCompound: {
      // The thinnest part sets the smallest dimension; the reach of them all, the largest.
      ShapeSpan span{"shape.parts", std::numeric_limits<double>::infinity(), "shape.parts"};
      const auto parts = shape.compound()->parts();
      for (std::size_t i = 0; i < parts.size(); ++i) {
        const ShapeSpan part = span_of(parts[i].shape);
        if (part.smallest < span.smallest)
          span = {"shape.parts[" + std::to_string(i) + "]." + part.smallest_field.substr(6),
                  part.smallest, "shape.parts"};
      }
      return span;
    }
    case ShapeType::kHalfSpace:
      break;
  }
  return {"shape", 0, "shape"};
}

constexpr LimitField kLimitFields[] = {
    {"max_coordinate", &WorldLimits::max_coordinate},
    {"min_size", &WorldLimits::min_size},
    {"max_size", &WorldLimits::max_size},
    {"min_mass", &WorldLimits::min_mass},
    {"max_mass", &WorldLimits::max_mass},
    {"max_linear_speed", &WorldLimits::max_linear_speed},
    {"max_angular_speed", &WorldLimits::max_angular_speed},
    {"max_time_step", &WorldLimits::max_time_step},
};

}  // namespace

Status check_time_step(double dt, const WorldLimits& limits) {
  char message[128];
  if (!std::isfinite(dt) || !(dt >= kMinTimeStep)) {
    std::snprintf(message, sizeof message,
                  "dt: %g s; it must be finite and at least %g s (the shortest step)", dt,
                  kMinTimeStep);
    return Status::error(message);
  }
  if (dt > limits.max_time_step) {
    std::snprintf(message, sizeof message, "dt: %g s is above limits.max_time_step (%g s)", dt,
                  limits.max_time_step);
    return Status::error(message);
  }
  return Status::ok();
}

std::span<const LimitField> limit_fields() {
  return kLimitFields;
}

Status validate(const WorldLimits& l) {
  for (const LimitField& field : kLimitFields)
    if (const double value = l.*field.value; !(value > 0) || !std::isfinite(value))
      return Status::error(std::string(field.name) + ": must be finite and > 0");
  if (!(l.min_size <= l.max_size)) return Status::error("max_size: must be >= min_size");
  if (!(l.min_mass <= l.max_mass)) return Status::error("max_mass: must be >= min_mass");
  // Beyond these a product of two limits (an impulse, a moment arm times a speed) could overflow.
  if (l.max_coordinate > 1e15) return Status::error("max_coordinate: must be <= 1e15");
  if (l.max_size > 1e12) return Status::error("max_size: must be <= 1e12");
  if (l.max_mass > 1e30 || l.min_mass < 1e-30)
    return Status::error("min_mass, max_mass: must be within [1e-30, 1e30]");
  if (l.max_linear_speed > 1e12 || l.max_angular_speed > 1e12)
    return Status::error("max_linear_speed, max_angular_speed: must be <= 1e12");
  return Status::ok();
}

double speed_of(const Vec3& velocity) {
  return std::hypot(velocity.x(), velocity.y(), velocity.z());
}

Status check_speeds(const Vec3& linear_velocity, const Vec3& angular_velocity,
                    const WorldLimits& limits) {
  if (!is_finite(linear_velocity)) return Status::error("linear_velocity: must be finite");
  if (!is_finite(angular_velocity)) return Status::error("angular_velocity: must be finite");
  if (const double v = speed_of(linear_velocity); v > limits.max_linear_speed)
    return above("linear_velocity", v, "m/s", "max_linear_speed", limits.max_linear_speed);
  if (const double w = speed_of(angular_velocity); w > limits.max_angular_speed)
    return above("angular_velocity", w, "rad/s", "max_angular_speed", limits.max_angular_speed);
  return Status::ok();
}

Status check_held_forces(const Vec3& force, const Vec3& torque, double inverse_mass,
                         const Mat3& inverse_inertia_world, const WorldLimits& limits) {
  if (!is_finite(force)) return Status::error("force: must be finite");
  if (!is_finite(torque)) return Status::error("torque: must be finite");
  // One longest step of the force alone, from rest, stays within the speed limits (the step
  // holds speeds at them anyway; this refuses a request that could only mean a mistake).
  if (const double dv = speed_of(force) * inverse_mass * limits.max_time_step;
      !(dv <= limits.max_linear_speed))
    return Status::error("force: it would change the speed by " + std::to_string(dv) +
                         " m/s in limits.max_time_step, above limits.max_linear_speed");
  if (const double dw = speed_of(inverse_inertia_world * torque) * limits.max_time_step;
      !(dw <= limits.max_angular_speed))
    return Status::error("torque: it would change the spin by " + std::to_string(dw) +
                         " rad/s in limits.max_time_step, above limits.max_angular_speed");
  return Status::ok();
}

namespace {

// Both check_limits read a body through these getters (a Body's fields, or a view's).
template <class AnyBody>
Status check_body_limits(const AnyBody& body, const WorldLimits& limits) {
  const Vec3 position = body.position();
  if (!is_finite(position)) return Status::error("position: must be finite");
  for (int k = 0; k < 3; ++k)
    if (std::abs(position[k]) > limits.max_coordinate)
      return above("position[" + std::to_string(k) + "]", std::abs(position[k]), "m",
                   "max_coordinate", limits.max_coordinate);
  const Shape& shape = body.shape();
  if (shape.type() != ShapeType::kHalfSpace) {
    const ShapeSpan span = span_of(shape);
    if (!(span.smallest >= limits.min_size))
      return below(span.smallest_field, span.smallest, "m", "min_size", limits.min_size);
    if (const double largest = shape.outer_radius(); !(largest <= limits.max_size))
      return above(span.largest_field, largest, "m", "max_size", limits.max_size);
  }
  if (body.is_static()) return Status::ok();
  if (body.is_kinematic())
    return check_speeds(body.linear_velocity(), body.angular_velocity(), limits);
  const double mass = body.mass();
  if (!(mass >= limits.min_mass)) return below("mass", mass, "kg", "min_mass", limits.min_mass);
  if (!(mass <= limits.max_mass)) return above("mass", mass, "kg", "max_mass", limits.max_mass);
  if (Status s = check_held_forces(body.force(), body.torque(), body.inverse_mass(),
                                   body.inverse_inertia_world(), limits);
      !s)
    return s;
  return check_speeds(body.linear_velocity(), body.angular_velocity(), limits);
}

// A Body's fields through the getters check_body_limits reads.
struct BodyFields {
  const Body& body;
  Vec3 position() const { return body.position; }
  const Shape& shape() const { return body.shape; }
  bool is_static() const { return body.is_static(); }
  bool is_kinematic() const { return body.is_kinematic(); }
  double mass() const { return body.mass; }
  Vec3 linear_velocity() const { return body.linear_velocity; }
  Vec3 angular_velocity() const { return body.angular_velocity; }
  Vec3 force() const { return body.force; }
  Vec3 torque() const { return body.torque; }
  double inverse_mass() const { return body.inverse_mass; }
  Mat3 inverse_inertia_world() const { return body.inverse_inertia_world; }
};

}  // namespace

Status check_limits(const Body& body, const WorldLimits& limits) {
  return check_body_limits(BodyFields{body}, limits);
}

Status check_definition(const BodyDef& def, const WorldLimits& limits) {
  Result<Body> body = make_body(def);
  if (!body) return body.status();
  return check_limits(body.value(), limits);
}

Status check_limits(BodyView body, const WorldLimits& limits) {
  return check_body_limits(body, limits);
}

}  // namespace tumble
