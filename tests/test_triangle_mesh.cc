// Triangle meshes: refusals that name the field; adjacency and which edges may push; bodies at
// rest on a triangulated floor where they rest on the plane, and a sliding box stopping where it
// stops on the plane; terrain as a mesh giving what the heightfield gives; one-sided triangles
// (a room's inside, a cube's outside, a box hanging over an edge); rays against brute force;
// bounded work for a huge body; snapshots bit for bit.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "physics/world.h"
#include "terrain_support.h"

namespace tumble {
namespace {

using namespace terrain_testing;

TriangleMeshDef mesh_of(const HeightFieldDef& def) {
  return mesh_of_height_field(HeightField::create(def).value());
}

// The box [-h, h]^3 as 12 triangles facing out (or in, for a room).
TriangleMeshDef cube_mesh(const Vec3& h, bool facing_in) {
  TriangleMeshDef mesh;
  for (int k = 0; k < 8; ++k)
    mesh.vertices.push_back(
        Vec3(k & 1 ? h.x() : -h.x(), k & 2 ? h.y() : -h.y(), k & 4 ? h.z() : -h.z()));
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  }
  if (facing_in)
    for (auto& t : mesh.triangles)
      std::swap(t[1], t[2]);
  return mesh;
}

// The standard terrain scene's rolling hills (terrain:N), `samples` a side 0.5 m apart: every
// edge turns by about 1.4°, too gently to be active.
HeightFieldDef rolling_hills(std::uint32_t samples) {
  return field_of(samples, samples, 0.5, [](double x, double y) {
    return 0.4 * std::sin(0.35 * x) * std::cos(0.3 * y) + 0.15 * std::sin(0.9 * x + 0.7 * y);
  });
}

std::string refusal(const TriangleMeshDef& def) {
  const Result<Shape> shape = Shape::create(def);
  return shape ? "" : shape.status().message();
}

TEST(TriangleMesh, RefusesBadDefinitionsNamingTheField) {
  const TriangleMeshDef good = cube_mesh(Vec3(1, 1, 1), false);
  EXPECT_EQ(refusal(good), "");
  EXPECT_NE(refusal(TriangleMeshDef{good.vertices, {}}).find("triangles: a mesh needs"),
            std::string::npos);
  TriangleMeshDef bad = good;
  bad.triangles[5][2] = 8;
  EXPECT_NE(refusal(bad).find("triangles[5]: vertex 8 of 8"), std::string::npos) << refusal(bad);
  bad = good;
  bad.triangles[3] = {1, 1, 2};
  EXPECT_NE(refusal(bad).find("triangles[3]: degenerate"), std::string::npos);
  bad = good;
  bad.vertices.push_back(Vec3(0.5, 0.5, 0.5));
  bad.triangles.push_back({0, 7, 8});  // the three in a line
  EXPECT_NE(refusal(bad).find("triangles[12]: degenerate"), std::string::npos);
  bad = good;
  bad.vertices[4].y() = std::nan("");
  EXPECT_NE(refusal(bad).find("vertices[4]: must be finite"), std::string::npos);
  bad = good;
  bad.vertices[2].x() = 2e6;
  EXPECT_NE(refusal(bad).find("vertices[2]"), std::string::npos);
  bad = good;
  bad.vertices.resize(kMaxMeshVertices + 1, Vec3::Zero());
  EXPECT_NE(refusal(bad).find("vertices: 2097153, more than the 2097152"), std::string::npos);
  // A mesh is static only.
  World world;
  BodyDef def;
  def.shape = good;
  def.mass = 1;
  const Result<BodyId> dynamic = world.create_body(def);
  ASSERT_FALSE(dynamic);
  EXPECT_EQ(dynamic.status().message(), "type: a mesh must be static");
  EXPECT_EQ(world.body_count(), 0u);
}

TEST(TriangleMesh, KnowsItsNeighboursAndWhichEdgesAreConvex) {
  const TriangleMesh cube = TriangleMesh::create(cube_mesh(Vec3(1, 2, 3), false)).value();
  for (std::size_t t = 0; t < cube.triangle_count(); ++t) {
    for (int e = 0; e < 3; ++e) {
      const std::int64_t other = cube.neighbour(t, e);
      ASSERT_GE(other, 0) << t << " " << e;  // closed
      const bool diagonal = cube.normal(t).dot(cube.normal(static_cast<std::size_t>(other))) > 0.5;
      // A face's diagonal is flat: inactive; the cube's edges are convex: active.
      EXPECT_EQ((cube.active_edges(t) >> e) & 1, diagonal ? 0 : 1) << t << " " << e;
    }
  }
  // Inside out, every edge is concave: none is active.
  const TriangleMesh room = TriangleMesh::create(cube_mesh(Vec3(1, 2, 3), true)).value();
  for (std::size_t t = 0; t < room.triangle_count(); ++t)
    EXPECT_EQ(room.active_edges(t), 0) << t;
  // A triangle wound against its neighbours joins none of them: its edges are boundaries.
  TriangleMeshDef flipped = cube_mesh(Vec3(1, 1, 1), false);
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  const TriangleMesh open = TriangleMesh::create(flipped).value();
  for (int e = 0; e < 3; ++e) {
    EXPECT_EQ(open.neighbour(0, e), -1);
    EXPECT_EQ((open.active_edges(0) >> e) & 1, 1);
  }
}

TEST(TriangleMesh, BodiesRestOnATriangulatedFloorAsOnThePlane) {
  const TriangleMeshDef floor = mesh_of(field_of(21, 21, 0.5, [](double, double) { return 0.0; }));
  for (const ShapeDef& body : {ShapeDef{BoxDef{Vec3(0.3, 0.2, 0.1)}}, ShapeDef{SphereDef{0.2}},
                               ShapeDef{CapsuleDef{0.1, 0.3}}}) {
    const Vec3 at(0.13, -0.41, 0.5);
    EXPECT_NEAR(rest_height(floor, body, at), rest_height(HalfSpaceDef{}, body, at), 1e-9);
  }
}

TEST(TriangleMesh, SlidingBoxStopsWhereItStopsOnThePlane) {
  // Across a floor of 0.5 m cells (slide_stop).
  const TriangleMeshDef floor = mesh_of(field_of(81, 81, 0.5, [](double, double) { return 0.0; }));
  const Vec3 on_plane = slide_stop(HalfSpaceDef{});
  const Vec3 on_mesh = slide_stop(floor);
  EXPECT_GT((on_plane - Vec3(kSlideStartX, kSlideStartY, 0.25)).norm(), 2.0);  // it did slide
  EXPECT_LT((on_mesh - on_plane).norm(), 1e-6);
}

TEST(TriangleMesh, SphereAndBoxRestInAValleyAndOnARidgeAsOnTheHeightfield) {
  const double r = 0.3, slope = 0.5;
  const double a = std::atan(slope);
  const TriangleMeshDef valley =
      mesh_of(field_of(9, 9, 0.5, [&](double, double y) { return slope * std::abs(y); }));
  const TriangleMeshDef ridge =
      mesh_of(field_of(9, 9, 0.5, [&](double, double y) { return -slope * std::abs(y); }));
  EXPECT_NEAR(rest_height(valley, SphereDef{r}, Vec3(0.1, 0, 1)), r / std::cos(a), 1e-4);
  EXPECT_NEAR(rest_height(ridge, SphereDef{r}, Vec3(0.1, 0, 1)), r, 1e-4);
  EXPECT_NEAR(rest_height(ridge, BoxDef{Vec3(0.2, 0.2, 0.1)}, Vec3(0.1, 0, 1)), 0.1, 1e-4);
}

// Over a convex edge too gentle to be active (3.4°, under kSmoothEdgeAngle), a vertex within the
// margin can lie beyond the feet of both triangles' normals: here 8 cm up and 2 mm past the edge,
// in the 4.8 mm wedge between them. The heightfield holds it by the triangle under it; the mesh
// must too (by where the line from the box's centre through it meets the surface): a box landing
// fast with such a vertex once sank 10 cm into the hills as a mesh and not as a heightfield.
TEST(TriangleMesh, AVertexOverAGentleConvexEdgeMeetsTheSurfaceAsOnTheHeightfield) {
  const HeightFieldDef field =
      field_of(9, 9, 0.5, [](double x, double) { return x <= 0 ? 0.0 : -0.06 * x; });
  for (const bool as_mesh : {false, true}) {
    WorldSettings settings;
    settings.collision.margin = 0.1;
    World world(settings);
    if (as_mesh)
      add_static(&world, mesh_of(field));
    else
      add_static(&world, field);
    // The bottom face 8 cm up: its two corners at x = 0.002 in the wedge, the two at x = 1.002
    // 14 cm over the slope, beyond the margin.
    add_dynamic(&world, BoxDef{Vec3(0.5, 0.5, 0.5)}, Vec3(0.502, 0, 0.58));
    int points = 0;
    for (const Contact& contact : world.find_contacts()) {
      for (int p = 0; p < contact.manifold.count; ++p) {
        const ContactPoint& point = contact.manifold.points[p];
        EXPECT_NEAR(std::abs(point.point_a.x() + point.point_b.x()) / 2, 0.002, 0.01) << as_mesh;
        EXPECT_NEAR(point.depth, -0.08, 1e-3) << as_mesh;
        ++points;
      }
    }
    EXPECT_EQ(points, 2) << (as_mesh ? "mesh" : "heightfield");
  }
}

// The same wedge under a ball or a capsule's core: over the apex of a ridge turning by 4.6°
// (inactive) the core's feet fall beyond both slopes, and the ball fell through the mesh (and sank
// 2 cm into the heightfield). The edge holds it there, at its radius above the apex, on both.
TEST(TriangleMesh, BallsAndCapsulesRestOnTheApexOfAGentleRidge) {
  const HeightFieldDef ridge =
      field_of(9, 9, 0.5, [](double, double y) { return -0.04 * std::abs(y); });
  const TriangleMeshDef mesh = mesh_of(ridge);
  for (const ShapeDef& ground : {ShapeDef{ridge}, ShapeDef{mesh}}) {
    EXPECT_NEAR(rest_height(ground, SphereDef{0.3}, Vec3(0.1, 0, 1)), 0.3, 1e-4);
    // A capsule lying along the ridge (its axis turned onto x), both core ends over the apex.
    World world;
    add_static(&world, ground);
    BodyDef capsule;
    capsule.shape = CapsuleDef{0.2, 0.5};
    capsule.mass = 1;
    capsule.position = Vec3(0.1, 0, 1);
    capsule.orientation = Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()));
    const BodyId id = world.create_body(capsule).value();
    run(&world, 120);
    EXPECT_NEAR(world.body(id)->position().z(), 0.2, 1e-4);
  }
}

// Balls and capsules thrown onto rolling hills (the standard terrain scene's, whose cells turn by
// about 1.4°: every edge gentle, none active) never sink into them: before gentle edges held a
// core in their wedge, balls of 0.25 m sank here up to 4.7 cm into the heightfield and 15 cm into
// the mesh, capsules 14 cm into either.
TEST(TriangleMesh, BallsAndCapsulesOnRollingHillsNeverSinkIntoThem) {
  const HeightFieldDef hills = rolling_hills(41);
  const HeightField surface = HeightField::create(hills).value();
  for (const ShapeDef& ground : {ShapeDef{hills}, ShapeDef{mesh_of(hills)}}) {
    World world;
    add_static(&world, ground);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> across(-7, 7), sideways(-3, 3);
    std::vector<BodyId> bodies;
    for (int k = 0; k < 64; ++k) {
      BodyDef body;
      body.mass = 1;
      body.shape = k % 2 == 0 ? ShapeDef{SphereDef{0.25}} : ShapeDef{CapsuleDef{0.15, 0.3}};
      body.position = Vec3(across(random), across(random), 1.5 + 0.02 * k);
      body.linear_velocity = Vec3(sideways(random), sideways(random), -5);
      body.orientation = Quat(Eigen::AngleAxisd(
          across(random), Vec3(sideways(random), sideways(random), 1).normalized()));
      bodies.push_back(world.create_body(body).value());
    }
    // How far the surface lies above a core's lowest end, less the radius (vertically: a bound
    // on the depth along the normal).
    double deepest[2] = {-1, -1};
    for (int step = 0; step < 300; ++step) {
      run(&world, 1);
      for (std::size_t k = 0; k < bodies.size(); ++k) {
        const BodyView body = world.body(bodies[k]);
        const bool capsule = k % 2 == 1;
        for (const double end : {-1.0, 1.0}) {
          const Vec3 core =
              body.position() + body.orientation() * Vec3(0, 0, capsule ? 0.3 * end : 0.0);
          if (std::abs(core.x()) > 9.5 || std::abs(core.y()) > 9.5) continue;  // rolled off
          const double sink =
              surface.height_at(core.x(), core.y()) - core.z() + (capsule ? 0.15 : 0.25);
          deepest[capsule] = std::max(deepest[capsule], sink);
        }
      }
    }
    const bool mesh = std::holds_alternative<TriangleMeshDef>(ground);
    EXPECT_LT(deepest[0], 0.01) << (mesh ? "mesh" : "heightfield") << ": balls";
    EXPECT_LT(deepest[1], 0.03) << (mesh ? "mesh" : "heightfield") << ": capsules";
  }
}

// A hundred bodies of `shape` thrown from 3 m over a square of half side `half_span`, falling at
// `down` m/s, sideways at up to `sideways` m/s, turning at up to 10 rad/s about each axis.
std::vector<BodyId> throw_bodies(World* world, const ShapeDef& shape, double half_span,
                                 double sideways, double down) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> across(-half_span, half_span), unit(-1, 1);
  std::vector<BodyId> bodies;
  for (int k = 0; k < 100; ++k) {
    BodyDef body;
    body.mass = 1;
    body.shape = shape;
    body.position = Vec3(across(random), across(random), 3);
    body.linear_velocity = Vec3(sideways * unit(random), sideways * unit(random), -down);
    body.angular_velocity = 10 * Vec3(unit(random), unit(random), unit(random));
    bodies.push_back(world->create_body(body).value());
  }
  return bodies;
}

// Balls and capsules thrown at 100 m/s onto rolling hills are swept (continuous collision) and
// stop on them. The sweep asks for contacts with a margin of its whole motion, 1.7 m here, and
// an edge's contact with its normal clamped to the face's read a core level with an edge a metre
// off as touching it: the sweep took the pair for one the solver holds and let some through (3
// of these 200 through the mesh; on the standard scene's hills 3 balls and 6 capsules of 100
// through the mesh, 1 capsule through the heightfield).
TEST(TriangleMesh, FastBallsAndCapsulesNeverPassThroughTheHills) {
  const HeightFieldDef hills = rolling_hills(81);
  const HeightField surface = HeightField::create(hills).value();
  for (const ShapeDef& ground : {ShapeDef{hills}, ShapeDef{mesh_of(hills)}}) {
    for (const ShapeDef& shape : {ShapeDef{SphereDef{0.1}}, ShapeDef{CapsuleDef{0.05, 0.2}}}) {
      World world;
      add_static(&world, ground);
      const std::vector<BodyId> bodies = throw_bodies(&world, shape, 15, 30, 100);
      run(&world, 60);
      const bool mesh = std::holds_alternative<TriangleMeshDef>(ground);
      for (std::size_t k = 0; k < bodies.size(); ++k) {
        const Vec3 p = world.body(bodies[k]).position();
        if (std::abs(p.x()) > 19 || std::abs(p.y()) > 19) continue;  // bounced off the hills
        EXPECT_GT(p.z(), surface.height_at(p.x(), p.y()))
            << (mesh ? "mesh" : "heightfield") << " body " << k;
      }
    }
  }
}

// Boxes and dumbbells (two balls on one body) thrown at 100 to 300 m/s, turning, onto rolling
// hills stop on them. A box landing on one corner pivots about it (the solve stops the corner,
// not the box: 100 rad/s and more) or is sent along the surface, and its contacts, the planes of
// the triangles near where the step began, cannot hold where it goes: its centre crossed the
// surface, where no contact holds it (a mesh holds only bodies in front of it). The sweep took a
// pair touching at the start for the solver's and let 3 to 8 boxes of 100 through on the standard
// scene's hills; checked along the body's centre alone, a dumbbell whose balls sank beside it
// (docs/DYNAMICS.md, "Continuous collision").
TEST(TriangleMesh, FastBoxesAndCompoundsNeverPassThroughTheHills) {
  const HeightFieldDef hills = rolling_hills(121);  // the standard scene's
  const HeightField surface = HeightField::create(hills).value();
  CompoundDef dumbbell;
  dumbbell.parts = {{SphereDef{0.1}, Pose{Vec3(-0.15, 0, 0), Quat::Identity()}},
                    {SphereDef{0.1}, Pose{Vec3(0.15, 0, 0), Quat::Identity()}}};
  for (const ShapeDef& ground : {ShapeDef{hills}, ShapeDef{mesh_of(hills)}}) {
    for (const ShapeDef& shape : {ShapeDef{BoxDef{Vec3(0.1, 0.1, 0.1)}}, ShapeDef{dumbbell}}) {
      for (const double speed : {100.0, 150.0, 300.0}) {
        World world;
        add_static(&world, ground);
        const std::vector<BodyId> bodies = throw_bodies(&world, shape, 20, 0.3 * speed, speed);
        run(&world, 60);
        const bool mesh = std::holds_alternative<TriangleMeshDef>(ground);
        const bool box = std::holds_alternative<BoxDef>(shape);
        for (std::size_t k = 0; k < bodies.size(); ++k) {
          const BodyView body = world.body(bodies[k]);
          // Every ball's centre of a dumbbell, a box's centre.
          for (const double side : box ? std::vector<double>{0.0} : std::vector<double>{-1, 1}) {
            const Vec3 p = body.position() + body.orientation() * Vec3(0.15 * side, 0, 0);
            if (std::abs(p.x()) > 29 || std::abs(p.y()) > 29) continue;  // bounced off the hills
            EXPECT_GT(p.z(), surface.height_at(p.x(), p.y()))
                << (mesh ? "mesh, " : "heightfield, ") << (box ? "box" : "dumbbell") << " at "
                << speed << " m/s, body " << k;
          }
        }
      }
    }
  }
}

TEST(TriangleMesh, TrianglesHoldBodiesOnTheirFrontOnly) {
  // On a closed cube (facing out): a box rests on its top.
  EXPECT_NEAR(rest_height(cube_mesh(Vec3(1, 1, 0.5), false), BoxDef{Vec3(0.2, 0.2, 0.2)},
                          Vec3(0.3, -0.2, 1.2)),
              0.7, 1e-4);
  // Inside a room (facing in): a box rests on its floor, the ceiling above it no hindrance.
  EXPECT_NEAR(
      rest_height(cube_mesh(Vec3(2, 2, 1), true), BoxDef{Vec3(0.2, 0.2, 0.2)}, Vec3(0.3, -0.2, 0)),
      -0.8, 1e-4);
  // A box hanging two thirds of its length over the cube's top edge tips off it; the side its
  // lower corners come to lie behind never throws it sideways.
  World world;
  add_static(&world, cube_mesh(Vec3(1, 1, 0.5), false));
  const BodyId box = add_dynamic(&world, BoxDef{Vec3(0.3, 0.2, 0.1)}, Vec3(1.1, 0, 0.601));
  double fastest_sideways = 0;
  for (int k = 0; k < 60; ++k) {
    run(&world, 1);
    fastest_sideways = std::max(fastest_sideways, std::abs(world.body(box)->linear_velocity().y()));
    fastest_sideways = std::max(fastest_sideways, world.body(box)->linear_velocity().x());
  }
  EXPECT_LT(fastest_sideways, 1.0);
  EXPECT_LT(world.body(box)->position().z(), 0.4);  // it fell past the top
  EXPECT_GT(world.body(box)->position().x(), 1.0);  // beside the cube, not through it
}

TEST(TriangleMesh, RaysMeetTheNearestFrontAsBruteForceDoes) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  // Bumpy terrain and a closed cube floating over it: rays from everywhere, in every direction.
  TriangleMeshDef def = mesh_of(field_of(33, 25, 0.37, [&](double x, double y) {
    return 0.4 * std::sin(1.3 * x) * std::cos(0.9 * y) + 0.05 * unit(random);
  }));
  const TriangleMeshDef cube = cube_mesh(Vec3(1, 0.7, 0.4), false);
  const auto first = static_cast<std::uint32_t>(def.vertices.size());
  for (const Vec3& v : cube.vertices)
    def.vertices.push_back(v + Vec3(0.5, 0.2, 1.5));
  for (auto t : cube.triangles)
    def.triangles.push_back({t[0] + first, t[1] + first, t[2] + first});
  World world;
  const Vec3 at(2, -1, 0.5);
  add_static(&world, def, at);
  const TriangleMesh mesh = TriangleMesh::create(def).value();
  int hits = 0;
  for (int k = 0; k < 4000; ++k) {
    const Vec3 origin(5 * unit(random), 4 * unit(random), 1.5 + 2 * unit(random));
    const Vec3 direction = Vec3(unit(random), unit(random), unit(random)).normalized();
    RayCast ray;
    ray.origin = origin + at;
    ray.direction = direction;
    ray.max_distance = 10;
    const RayHit hit = world.cast_ray(ray).value();
    const double expected = brute_force_ray(
        mesh.triangle_count(), [&](std::size_t t) { return mesh.triangle(t); }, origin,
        direction, 10);
    ASSERT_EQ(hit.hit(), expected <= 10) << k;
    if (!hit.hit()) continue;
    EXPECT_NEAR(hit.distance, expected, 1e-9) << k;
    EXPECT_LT(hit.normal.dot(direction), 0) << k;
    ++hits;
  }
  EXPECT_GT(hits, 1000);
}

// The tree's nodes meet four children at once, lanes of which may be empty (a mesh of a few
// triangles) and rays along the axes give infinite and undefined slab distances: rays along
// every axis and diagonal from a grid of origins (some on the triangles' own coordinates) meet
// what the brute force meets, on meshes of 1 to 40 triangles and on terrain.
TEST(TriangleMesh, RaysAlongTheAxesAndOnMeshesOfAFewTrianglesMeetWhatBruteForceMeets) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(-1, 1);
  const TriangleMeshDef terrain = mesh_of(
      field_of(9, 7, 0.5, [&](double x, double y) { return 0.3 * std::sin(2 * x) * std::cos(y); }));
  for (const std::size_t count : {1, 2, 3, 5, 9, 17, 40, 96}) {
    TriangleMeshDef def;
    def.vertices = terrain.vertices;
    def.triangles.assign(terrain.triangles.begin(), terrain.triangles.begin() + count);
    const TriangleMesh mesh = TriangleMesh::create(def).value();
    World world;
    add_static(&world, def, Vec3::Zero());
    int hits = 0;
    for (double x = -2.5; x <= 2.5; x += 0.25) {
      for (double y = -2; y <= 2; y += 0.25) {
        for (const Vec3& direction : {Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0),
                                      Vec3(0, 0, 1), Vec3(1, 1, -1).normalized(),
                                      Vec3(1, 0, -1).normalized(), Vec3(0, -1, -1).normalized()}) {
          const Vec3 origin(x, y, 0.5 * unit(random) + (direction.z() < 0 ? 1.0 : -1.0));
          RayCast ray;
          ray.origin = origin;
          ray.direction = direction;
          ray.max_distance = 20;
          const RayHit hit = world.cast_ray(ray).value();
          const bool met = hit.hit();
          const double expected = brute_force_ray(
              mesh.triangle_count(), [&](std::size_t t) { return mesh.triangle(t); }, origin,
              direction, 20);
          ASSERT_EQ(met, expected <= 20) << count << " " << origin.transpose();
          if (!met) continue;
          EXPECT_NEAR(hit.distance, expected, 1e-9);
          ++hits;
        }
      }
    }
    EXPECT_GT(hits, 0) << count;
  }
}

// The numbers of the triangles TriangleMesh::triangles_meeting gives, in its order; false where
// they did not all fit (none of these boxes meets every triangle).
bool numbers_meeting(const TriangleMesh& mesh, const Aabb& box,
                     std::vector<std::uint32_t>* numbers) {
  std::vector<TriangleMesh::LeafTriangle> leaves;
  const bool complete = mesh.triangles_meeting(box, &leaves, mesh.triangle_count());
  numbers->clear();
  for (const TriangleMesh::LeafTriangle& leaf : leaves)
    numbers->push_back(leaf.triangle);
  return complete;
}

// The triangles a box meets: every triangle whose bounds meet the box, each once.
TEST(TriangleMesh, ABoxMeetsEveryTriangleWhoseBoundsItMeets) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  const TriangleMesh mesh =
      TriangleMesh::create(mesh_of(field_of(41, 37, 0.25, [&](double x, double y) {
        return 0.3 * std::sin(2 * x) * std::cos(y);
      }))).value();
  std::vector<std::uint32_t> found;
  for (int k = 0; k < 200; ++k) {
    const Vec3 centre(5 * unit(random), 4.5 * unit(random), 0.4 * unit(random));
    const Vec3 half =
        Vec3(0.05, 0.05, 0.05) + 0.3 * Vec3(1 + unit(random), 1 + unit(random), 1 + unit(random));
    const Aabb box{centre - half, centre + half};
    ASSERT_TRUE(numbers_meeting(mesh, box, &found));
    std::vector<char> seen(mesh.triangle_count(), 0);
    for (std::uint32_t t : found) {
      ASSERT_EQ(seen[t], 0) << t;
      seen[t] = 1;
    }
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      Aabb bounds;
      for (const Vec3& v : mesh.triangle(t))
        bounds.grow(v);
      const bool meets = (bounds.min.array() <= box.max.array()).all() &&
                         (box.min.array() <= bounds.max.array()).all();
      if (meets) {
        EXPECT_EQ(seen[t], 1) << k << " " << t;
      }
    }
  }
}

// The walk tests a node's four children in floats, the box rounded outwards: it must meet exactly
// the children the box's own (double) bounds meet. Boxes touching a child's bound exactly, and
// boxes one double below or above it (which round to that float to nearest) against a walk that
// compares in doubles: the same triangles in the same order.
TEST(TriangleMesh, TheWalkMeetsChildrenExactlyAsTheDoubleBoundsDo) {
  const TriangleMesh mesh =
      TriangleMesh::create(mesh_of(field_of(33, 29, 0.3, [&](double x, double y) {
        return 0.2 * std::sin(1.7 * x) * std::cos(1.3 * y);
      }))).value();
  const auto reference = [&](const Aabb& box) {
    std::vector<std::uint32_t> out;
    std::vector<std::array<std::uint32_t, 2>> stack{{0, 0}};
    while (!stack.empty()) {
      const auto [first, count] = stack.back();
      stack.pop_back();
      if (count != 0) {
        for (std::uint32_t k = first; k < first + count; ++k)
          out.push_back(mesh.leaf_triangle(k).triangle);
        continue;
      }
      const TriangleMesh::Node& node = mesh.nodes()[first];
      for (int k = 0; k < 4; ++k) {
        bool meets = node.count[k] != TriangleMesh::kNoChild;
        for (int axis = 0; axis < 3; ++axis)
          meets = meets && double{node.min[axis][k]} <= box.max[axis] &&
                  box.min[axis] <= double{node.max[axis][k]};
        if (meets) stack.push_back({node.first[k], node.count[k]});
      }
    }
    return out;
  };
  std::vector<std::uint32_t> found;
  int differing_from_touching = 0;
  for (std::size_t n = 0; n < mesh.nodes().size(); ++n) {
    const TriangleMesh::Node& node = mesh.nodes()[n];
    for (int k = 0; k < 4; ++k) {
      if (node.count[k] == TriangleMesh::kNoChild) continue;
      Aabb child;
      for (int axis = 0; axis < 3; ++axis) {
        child.min[axis] = node.min[axis][k];
        child.max[axis] = node.max[axis][k];
      }
      for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side < 2; ++side) {
          // The box beyond the child's bound on this axis, touching it or one double short.
          const double bound = side == 0 ? child.min[axis] : child.max[axis];
          const double away = side == 0 ? -HUGE_VAL : HUGE_VAL;
          for (const double face : {bound, std::nextafter(bound, away)}) {
            Aabb box = child;
            box.min[axis] = side == 0 ? face - 0.1 : face;
            box.max[axis] = side == 0 ? face : face + 0.1;
            const std::vector<std::uint32_t> expected = reference(box);
            ASSERT_TRUE(numbers_meeting(mesh, box, &found));
            ASSERT_EQ(found, expected) << n << " " << k << " " << axis << " " << side;
            differing_from_touching += face != bound && expected != reference(child);
          }
        }
      }
    }
  }
  // One double short of a child, the box misses it: the walks must have told such boxes apart.
  EXPECT_GT(differing_from_touching, 100);
}

// 64 boxes dropped on bumpy terrain made a mesh: no centre ever comes nearer the surface under
// it than half a box's thickness allows, and they come to rest.
TEST(TriangleMesh, PileOfBoxesComesToRestOnTerrainMadeAMesh) {
  const TriangleMeshDef def = mesh_of(field_of(41, 41, 0.5, [](double x, double y) {
    return 0.3 * std::sin(0.8 * x) * std::sin(0.7 * y) + 0.1 * std::cos(2.1 * x + 0.3 * y);
  }));
  World world;
  add_static(&world, def);
  std::vector<BodyId> bodies;
  for (int k = 0; k < 64; ++k) {
    const Vec3 at(-3.5 + (k % 8), -3.5 + (k / 8) % 8, 1.5 + 0.2 * (k % 3));
    bodies.push_back(add_dynamic(&world, BoxDef{Vec3(0.2, 0.15, 0.1)}, at));
  }
  World terrain;
  add_static(&terrain, def);
  for (int chunk = 0; chunk < 15; ++chunk) {
    run(&world, 20);
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      const BodyView body = world.body(bodies[k]);
      RayCast down;
      down.origin = body.position() + Vec3(0, 0, 5);
      down.direction = -Vec3::UnitZ();
      down.max_distance = 20;
      const RayHit surface = terrain.cast_ray(down).value();
      ASSERT_TRUE(surface.hit());
      EXPECT_GT(body.position().z() - surface.point.z(), 0.05) << k << " at " << chunk;
      if (chunk == 14) {
        EXPECT_LT(body.linear_velocity().norm(), 1e-3) << k;
      }
    }
  }
}

// A body over more triangles than a pair may visit is met on the first kMaxTerrainTriangles of
// them, and the narrow phase says so; a body over fewer is met whole and raises nothing.
TEST(TriangleMesh, AHugeBodyVisitsABoundedNumberOfTrianglesAndSaysSo) {
  const Shape mesh =
      Shape::create(mesh_of(field_of(401, 401, 0.5, [](double, double) { return 0.0; }))).value();
  const Shape huge = Shape::create(BoxDef{Vec3(90, 90, 1)}).value();
  const Shape small = Shape::create(BoxDef{Vec3(1, 1, 1)}).value();
  ContactManifold manifold;
  const Pose ground;
  const Pose resting{Vec3(0, 0, 0.999), Quat::Identity()};
  EXPECT_NE(
      collide(huge, resting, mesh, ground, CollisionSettings{}, &manifold) & kTerrainCellLimit, 0u);
  EXPECT_EQ(collide(small, resting, mesh, ground, CollisionSettings{}, &manifold), 0u);
  EXPECT_EQ(manifold.count, 4);
  EXPECT_NEAR(manifold.depth, 0.001, 1e-12);
}

TEST(TriangleMesh, SnapshotsStepBitForBit) {
  const TriangleMeshDef def = mesh_of(
      field_of(17, 13, 0.6, [](double x, double y) { return 0.2 * std::sin(x) * std::cos(y); }));
  World world;
  add_static(&world, def, Vec3(0.5, 0, -0.2));
  for (int k = 0; k < 12; ++k)
    add_dynamic(&world, BoxDef{Vec3(0.2, 0.2, 0.2)}, Vec3(-2 + 0.8 * (k % 6), (k / 6) - 0.5, 1));
  run(&world, 40);
  const std::string saved = world.save_state();
  World copy;
  ASSERT_TRUE(copy.restore_state(saved).is_ok());
  EXPECT_EQ(copy.save_state(), saved);
  run(&world, 30);
  run(&copy, 30);
  EXPECT_EQ(copy.save_state(), world.save_state());
}

}  // namespace
}  // namespace tumble
