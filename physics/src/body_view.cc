// The accessors live here, not in the header, so that the header need not show how a body is
// stored.
#include "physics/body_view.h"

#include "body_state.h"

namespace tumble {

const Body& BodyView::body() const {
  TUMBLE_ASSERT(body_ != nullptr);
  return *body_;
}

BodyType BodyView::type() const {
  return body().type;
}
bool BodyView::is_static() const {
  return body().is_static();
}

bool BodyView::is_kinematic() const {
  return body().is_kinematic();
}
bool BodyView::asleep() const {
  return body().asleep;
}
bool BodyView::is_moving() const {
  return body().is_moving();
}
const Shape& BodyView::shape() const {
  return body().shape;
}
double BodyView::mass() const {
  return body().mass;
}
double BodyView::inverse_mass() const {
  return body().inverse_mass;
}
Mat3 BodyView::inertia_body() const {
  return body().inertia_body;
}
Mat3 BodyView::inverse_inertia_world() const {
  return body().inverse_inertia_world;
}
double BodyView::friction() const {
  return body().friction;
}
double BodyView::restitution() const {
  return body().restitution;
}
double BodyView::gravity_scale() const {
  return body().gravity_scale;
}
double BodyView::linear_damping() const {
  return body().linear_damping;
}
double BodyView::angular_damping() const {
  return body().angular_damping;
}
Vec3 BodyView::force() const {
  return body().force;
}
Vec3 BodyView::torque() const {
  return body().torque;
}
CollisionFilter BodyView::filter() const {
  return body().filter;
}
Vec3 BodyView::position() const {
  return body().position;
}
Quat BodyView::orientation() const {
  return body().orientation;
}
Pose BodyView::pose() const {
  return body().pose();
}
Vec3 BodyView::linear_velocity() const {
  return body().linear_velocity;
}
Vec3 BodyView::angular_velocity() const {
  return body().angular_velocity;
}

}  // namespace tumble
