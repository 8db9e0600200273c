// Shapes and bodies: validation messages, convex hulls, exact mass properties, and the world's
// all-or-nothing creation.
#include <cmath>

#include <gtest/gtest.h>

#include "physics/world.h"
#include "test_support.h"

namespace tumble {
namespace {

TEST(Shapes, RefusesBadDefinitionsNamingTheField) {
  EXPECT_EQ(Shape::create(SphereDef{0}).error(), "radius: must be > 0");
  EXPECT_EQ(Shape::create(SphereDef{NAN}).error(), "radius: must be finite");
  EXPECT_EQ(Shape::create(CapsuleDef{0.1, -1}).error(), "half_height: must be > 0");
  EXPECT_EQ(Shape::create(BoxDef{Vec3(1, 0, 1)}).error(), "half_extents[1]: must be > 0");
  EXPECT_EQ(Shape::create(BoxDef{Vec3(1, 1, INFINITY)}).error(), "half_extents[2]: must be finite");
  EXPECT_EQ(Shape::create(HullDef{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}}).error(),
            "points: a hull needs at least 4 points");
  const std::vector<Vec3> flat = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0),
                                  Vec3(0.5, 0.5, 0)};
  EXPECT_EQ(Shape::create(HullDef{flat}).error(),
            "points: coplanar or collinear (degenerate hull)");
  EXPECT_EQ(Shape::create(HullDef{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, NAN)}})
                .error(),
            "points[3]: must be finite");
}

TEST(Shapes, HullOfCubeWithDuplicatesAndCoplanarPointsIsTheCube) {
  std::vector<Vec3> points;
  for (int i = 0; i < 8; ++i)
    points.emplace_back((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
  points.push_back(points[0]);       // duplicate
  points.emplace_back(0, 0, 1);      // on a face
  points.emplace_back(1, 0, 0);      // on a face
  points.emplace_back(1, 1, 0);      // on an edge
  points.emplace_back(0.2, 0.1, 0);  // inside
  const Shape hull = Shape::create(HullDef{points}).value();
  const ConvexPolyhedron& p = *hull.polyhedron();
  EXPECT_EQ(p.vertices.size(), 8u);
  EXPECT_EQ(p.faces.size(), 6u);
  EXPECT_EQ(p.edges.size(), 12u);
  EXPECT_NEAR(hull.volume(), 8.0, 1e-12);
  // Every face is a counter-clockwise quad whose plane holds its vertices.
  for (const auto& face : p.faces) {
    ASSERT_EQ(face.count, 4u);
    const Vec3 winding = (p.face_vertex(face, 1) - p.face_vertex(face, 0))
                             .cross(p.face_vertex(face, 2) - p.face_vertex(face, 1));
    EXPECT_GT(winding.dot(face.normal), 0);
    for (std::uint32_t k = 0; k < 4; ++k)
      EXPECT_NEAR(face.normal.dot(p.face_vertex(face, k)), face.offset, 1e-12);
  }
  const MassProperties hull_mass = hull.mass_properties(2.0);
  const MassProperties box_mass = Shape::create(BoxDef{Vec3::Ones()}).value().mass_properties(2.0);
  EXPECT_NEAR(hull_mass.mass, box_mass.mass, 1e-12);
  EXPECT_TRUE(hull_mass.inertia.isApprox(box_mass.inertia, 1e-12));
  EXPECT_LT(hull_mass.center_of_mass.norm(), 1e-12);
}

TEST(Shapes, TetrahedronMassPropertiesMatchClosedForm) {
  // Corner tetrahedron (0, e1, e2, e3) with a = 1: volume 1/6, centroid 1/4, and
  // about the centroid I_xx = m * 3/80 * (a^2 + a^2) and I_xy = m * 1/80 * a^2 (Tonon 2004).
  const Shape tetra =
      Shape::create(HullDef{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}}).value();
  const MassProperties props = tetra.mass_properties(6.0);  // mass 1
  EXPECT_NEAR(props.mass, 1.0, 1e-12);
  EXPECT_TRUE(props.center_of_mass.isApprox(Vec3::Constant(0.25), 1e-12));
  EXPECT_NEAR(props.inertia(0, 0), 3.0 / 80.0 * 2, 1e-12);
  EXPECT_NEAR(props.inertia(0, 1), 1.0 / 80.0, 1e-12);
}

// Inertia by brute-force integration over a fine grid of cells, for shapes with closed forms.
Mat3 integrate_inertia(const Shape& shape, double density, int cells) {
  const Aabb box = shape.local_bounds();
  const Vec3 step = box.extent() / cells;
  Mat3 inertia = Mat3::Zero();
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j)
      for (int k = 0; k < cells; ++k) {
        const Vec3 p = box.min + step.cwiseProduct(Vec3(i + 0.5, j + 0.5, k + 0.5));
        // Inside test: distance to the core segment (a sphere's core is a point).
        const double r = shape.radius();
        const Vec3 core(0, 0, std::clamp(p.z(), -shape.half_height(), shape.half_height()));
        if ((p - core).norm() > r) continue;
        const double dm = density * step.prod();
        inertia += dm * (p.squaredNorm() * Mat3::Identity() - p * p.transpose());
      }
  return inertia;
}

TEST(Shapes, CapsuleAndSphereInertiaMatchIntegration) {
  const Shape capsule = Shape::create(CapsuleDef{0.3, 0.7}).value();
  const Mat3 numeric = integrate_inertia(capsule, 1000, 160);
  const Mat3 exact = capsule.mass_properties(1000).inertia;
  EXPECT_NEAR(numeric(0, 0) / exact(0, 0), 1.0, 2e-3);
  EXPECT_NEAR(numeric(2, 2) / exact(2, 2), 1.0, 2e-3);
  const Shape sphere = Shape::create(SphereDef{0.5}).value();
  EXPECT_NEAR(sphere.mass_properties(1.0).inertia(1, 1), 0.4 * sphere.volume() * 0.25, 1e-12);
}

TEST(Shapes, BoxInertiaIsTheStandardFormula) {
  const MassProperties p =
      Shape::create(BoxDef{Vec3(0.5, 1, 1.5)}).value().mass_properties(1.0 / 6.0);
  EXPECT_NEAR(p.mass, 1.0, 1e-12);
  EXPECT_NEAR(p.inertia(0, 0), (4 + 9) / 12.0, 1e-12);
  EXPECT_NEAR(p.inertia(1, 1), (1 + 9) / 12.0, 1e-12);
  EXPECT_NEAR(p.inertia(2, 2), (1 + 4) / 12.0, 1e-12);
}

// Boxes of one size share one polyhedron (a pile of equal boxes reads one in its narrow phase);
// another size gets its own, and one made again after every holder is gone is whole.
TEST(Shapes, BoxesOfOneSizeShareTheirPolyhedron) {
  const Shape a = Shape::create(BoxDef{Vec3(0.5, 0.25, 1.0)}).value();
  const Shape b = Shape::create(BoxDef{Vec3(0.5, 0.25, 1.0)}).value();
  const Shape c = Shape::create(BoxDef{Vec3(0.5, 0.25, 1.0 + 1e-12)}).value();
  ASSERT_NE(a.polyhedron(), nullptr);
  EXPECT_EQ(a.polyhedron(), b.polyhedron());
  EXPECT_NE(a.polyhedron(), c.polyhedron());
  EXPECT_EQ(c.polyhedron()->vertices[7], Vec3(0.5, 0.25, 1.0 + 1e-12));
  // Many sizes made and dropped (their entries swept as they accumulate), then one made again.
  for (int k = 1; k <= 1000; ++k)
    ASSERT_TRUE(Shape::create(BoxDef{Vec3::Constant(0.001 * k)}));
  const Shape d = Shape::create(BoxDef{Vec3::Constant(0.5)}).value();
  ASSERT_EQ(d.polyhedron()->vertices.size(), 8u);
  EXPECT_EQ(d.polyhedron()->vertices[7], Vec3::Constant(0.5));
  EXPECT_EQ(d.polyhedron()->faces.size(), 6u);
}

// A rock of 40 points on a lumpy ellipsoid, some inside the hull: the shared hull must be the
// one these points build, interior points and all.
std::vector<Vec3> rock_points(double squash) {
  std::vector<Vec3> points;
  for (int i = 0; i < 40; ++i) {
    const double z = 1 - (2 * i + 1) / 40.0, r = std::sqrt(1 - z * z), a = 2.399963 * i;
    const double lump = 0.9 + 0.1 * std::sin(7.0 * i);
    points.emplace_back(0.4 * lump * r * std::cos(a), 0.3 * lump * r * std::sin(a),
                        squash * lump * z + 0.05);
  }
  return points;
}

TEST(Shapes, HullsOfOnePointSetShareTheirPolyhedra) {
  const std::vector<Vec3> points = rock_points(0.2);
  std::vector<Vec3> nudged = points;
  nudged[3].x() = std::nextafter(nudged[3].x(), 1.0);
  const Shape a = Shape::create(HullDef{points}).value();
  const Shape b = Shape::create(HullDef{points}).value();
  const Shape c = Shape::create(HullDef{nudged}).value();
  ASSERT_NE(a.polyhedron(), nullptr);
  EXPECT_EQ(a.polyhedron(), b.polyhedron());
  EXPECT_NE(a.polyhedron(), c.polyhedron());

  // Moved to a centre of mass: one copy for every shape moved by the same offset, and exactly the
  // copy a shape of its own would make.
  const Vec3 offset(0.01, -0.02, 0.05);
  const Shape moved_a = a.recentred(offset);
  const Shape moved_b = b.recentred(offset);
  const Shape moved_other = a.recentred(Vec3(0.01, -0.02, 0.06));
  EXPECT_EQ(moved_a.polyhedron(), moved_b.polyhedron());
  EXPECT_NE(moved_a.polyhedron(), moved_other.polyhedron());
  ASSERT_EQ(moved_a.polyhedron()->vertices.size(), a.polyhedron()->vertices.size());
  for (std::size_t i = 0; i < a.polyhedron()->vertices.size(); ++i)
    EXPECT_EQ(moved_a.polyhedron()->vertices[i], a.polyhedron()->vertices[i] - offset);
  for (std::size_t i = 0; i < a.polyhedron()->faces.size(); ++i)
    EXPECT_EQ(moved_a.polyhedron()->faces[i].offset,
              a.polyhedron()->faces[i].offset - a.polyhedron()->faces[i].normal.dot(offset));

  // Bodies keep only the moved copies, and still share one hull: the last hulls built are kept.
  World world;
  std::vector<BodyDef> defs(3);
  for (int i = 0; i < 3; ++i) {
    defs[i].shape = HullDef{i < 2 ? points : nudged};
    defs[i].position = Vec3(i, 0, 1);
  }
  const std::vector<BodyId> ids = world.create_bodies(defs).value();
  EXPECT_EQ(world.body(ids[0]).shape().polyhedron(), world.body(ids[1]).shape().polyhedron());
  EXPECT_NE(world.body(ids[0]).shape().polyhedron(), world.body(ids[2]).shape().polyhedron());

  // Many other rocks made and dropped (the kept hulls and the maps' entries turned over), then
  // the first made again: the hull its points build.
  for (int k = 1; k <= 300; ++k) ASSERT_TRUE(Shape::create(HullDef{rock_points(0.2 + 1e-3 * k)}));
  const Shape d = Shape::create(HullDef{points}).value();
  EXPECT_EQ(d.polyhedron()->vertices, a.polyhedron()->vertices);
  EXPECT_EQ(d.polyhedron()->face_vertices, a.polyhedron()->face_vertices);
  // A refusal is the builder's, and nothing is kept of it.
  std::vector<Vec3> flat = points;
  for (Vec3& p : flat) p.z() = 0;
  EXPECT_FALSE(Shape::create(HullDef{flat}));
  EXPECT_FALSE(Shape::create(HullDef{flat}));
}

TEST(Bodies, RefusesBadDefinitionsNamingTheField) {
  BodyDef def;
  def.mass = -1;
  EXPECT_EQ(validate(def).message(), "mass: must be finite and >= 0");
  def = BodyDef();
  def.orientation = Quat(0, 0, 0, 0);
  EXPECT_EQ(validate(def).message(), "orientation: must be a unit quaternion (norm is 0.000000)");
  def = BodyDef();
  def.linear_velocity.y() = INFINITY;
  EXPECT_EQ(validate(def).message(), "linear_velocity[1]: must be finite");
  def = BodyDef();
  def.shape = HalfSpaceDef{};
  EXPECT_EQ(validate(def).message(), "type: a half_space must be static");
  def = BodyDef();
  def.restitution = 1.5;
  EXPECT_EQ(validate(def).message(), "restitution: must be in [0, 1]");
}

TEST(Bodies, NearlyUnitQuaternionIsNormalisedAndMassSetsInertia) {
  World world;
  BodyDef def;
  def.orientation = Quat(1.0005, 0, 0, 0);
  def.mass = 3;
  const BodyId id = world.create_body(def).value();
  const BodyView body = world.body(id);
  EXPECT_NEAR(body->orientation().norm(), 1.0, 1e-15);
  EXPECT_NEAR(body->mass(), 3.0, 1e-12);
  EXPECT_NEAR(body->inertia_body()(0, 0), 3.0 / 6.0, 1e-12);
}

TEST(Bodies, HullBodyIsPlacedAtItsCentreOfMass) {
  World world;
  BodyDef def;
  def.shape = HullDef{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}};
  def.position = Vec3(10, 0, 0);
  def.orientation = Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
  const BodyView body = world.body(world.create_body(def).value());
  EXPECT_TRUE(body->position().isApprox(Vec3(10 - 0.25, 0.25, 0.25), 1e-12));
  // The hull's vertices, placed by the body's pose, are where the definition put them.
  const Vec3 corner = body->pose().transform(body->shape().polyhedron()->vertices[0]);
  bool matches = false;
  for (const Vec3& p : std::get<HullDef>(def.shape).points)
    matches |= (corner - def.position - def.orientation * p).norm() < 1e-12;
  EXPECT_TRUE(matches);
}

TEST(World, BatchCreationIsAllOrNothing) {
  World world;
  std::vector<BodyDef> defs(5);
  for (int i = 0; i < 5; ++i)
    defs[i].position = Vec3(0, 0, 2.0 * i);
  defs[3].shape = BoxDef{Vec3(1, 1, -2)};
  const auto result = world.create_bodies(defs);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error(), "bodies[3].shape.half_extents[2]: must be > 0");
  EXPECT_EQ(world.body_count(), 0u);
  defs[3].shape = BoxDef{};
  ASSERT_TRUE(world.create_bodies(defs).ok());
  EXPECT_EQ(world.body_count(), 5u);
}

TEST(World, RemovedIdsGoStaleAndSlotsAreReused) {
  World world;
  const BodyId first = world.create_body(BodyDef{}).value();
  ASSERT_TRUE(world.remove_body(first).is_ok());
  EXPECT_FALSE(world.contains(first));
  EXPECT_FALSE(world.body(first));
  EXPECT_EQ(world.remove_body(first).message(), "body: no body with this id");
  const BodyId second = world.create_body(BodyDef{}).value();
  EXPECT_EQ(second.index, first.index);
  EXPECT_NE(second.generation, first.generation);
  EXPECT_FALSE(world.contains(first));
}

}  // namespace
}  // namespace tumble
