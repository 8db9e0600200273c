// The renderer off screen (OSMesa): a known box under a fixed camera lands on the pixels its
// projection says, the face turned to the light is brighter than the faces turned away, and a
// specular highlight appears where the light's reflection points at the camera.
#include <gtest/gtest.h>

#include <filesystem>

#include "height_field_mesh.h"
#include "hull_mesh.h"
#include "offscreen.h"
#ifdef TUMBLE_HAVE_WORLD_VIEW  // needs the API (proto/), built with the server
#include "world_view.h"
#endif
#include "renderer.h"

namespace tumble::viewer {
namespace {

constexpr int kWidth = 320, kHeight = 240;

struct Picture {
  std::vector<std::uint8_t> rgba;
  int brightness(int x, int y) const {  // sum of R, G, B at pixel (x, y), y from the top
    const std::size_t i = (static_cast<std::size_t>(y) * kWidth + x) * 4;
    return rgba[i] + rgba[i + 1] + rgba[i + 2];
  }
  bool is_background(int x, int y, const Lighting& l) const {
    const std::size_t i = (static_cast<std::size_t>(y) * kWidth + x) * 4;
    return std::abs(rgba[i] - l.background.x() * 255) < 2 &&
           std::abs(rgba[i + 1] - l.background.y() * 255) < 2 &&
           std::abs(rgba[i + 2] - l.background.z() * 255) < 2;
  }
};

// Where a world point lands, in pixels from the top left.
Eigen::Vector2f project(const Camera& camera, const Eigen::Vector3f& point) {
  const Eigen::Vector4f clip =
      camera.projection(static_cast<float>(kWidth) / kHeight) * camera.view() * point.homogeneous();
  const Eigen::Vector2f ndc = clip.head<2>() / clip.w();
  return {(ndc.x() + 1) / 2 * kWidth, (1 - ndc.y()) / 2 * kHeight};
}

class RenderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    ASSERT_TRUE(context_.create(kWidth, kHeight, &error)) << error;
    renderer_ = std::make_unique<Renderer>(context_.gl());
    ASSERT_TRUE(renderer_->init(&error)) << error;
  }
  // A grey unit cube (half extent 0.5) at the origin.
  Picture draw_cube(const Camera& camera, const Lighting& lighting, float grey = 0.6f) {
    std::vector<std::vector<Instance>> instances(3);
    Instance cube;
    cube.model.topLeftCorner<3, 3>() = Eigen::Matrix3f::Identity() * 0.5f;
    cube.colour = {grey, grey, grey, 1};
    instances[renderer_->box_mesh()].push_back(cube);
    renderer_->draw(instances, camera, lighting, kWidth, kHeight);
    return {context_.read_rgba()};
  }
  OffscreenContext context_;
  std::unique_ptr<Renderer> renderer_;
};

TEST_F(RenderTest, TheBoxCoversItsProjectionAndNothingElse) {
  Camera camera;
  camera.eye = {3, -4, 2.5f};
  camera.target = {0, 0, 0};
  Lighting lighting;
  const Picture picture = draw_cube(camera, lighting);
  // The centre of the cube and the centres of its three visible faces are covered.
  for (const Eigen::Vector3f& p : {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0, 0, 0.5f),
                                   Eigen::Vector3f(0, -0.5f, 0), Eigen::Vector3f(0.5f, 0, 0)}) {
    const Eigen::Vector2f at = project(camera, p);
    EXPECT_FALSE(
        picture.is_background(static_cast<int>(at.x()), static_cast<int>(at.y()), lighting))
        << p.transpose();
  }
  // Just outside each corner's projection, and the picture's corners, is background.
  int outside = 0, covered = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      (picture.is_background(x, y, lighting) ? outside : covered)++;
  EXPECT_TRUE(picture.is_background(0, 0, lighting));
  EXPECT_TRUE(picture.is_background(kWidth - 1, kHeight - 1, lighting));
  // The covered area matches the projected silhouette's bounding box roughly: more than a
  // hundredth of the picture and less than its half.
  EXPECT_GT(covered, kWidth * kHeight / 100);
  EXPECT_LT(covered, kWidth * kHeight / 2);
  Eigen::Vector2f lo(1e9f, 1e9f), hi(-1e9f, -1e9f);
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3f p(corner & 1 ? 0.5f : -0.5f, corner & 2 ? 0.5f : -0.5f,
                            corner & 4 ? 0.5f : -0.5f);
    const Eigen::Vector2f at = project(camera, p);
    lo = lo.cwiseMin(at);
    hi = hi.cwiseMax(at);
  }
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      if (x < lo.x() - 2 || x > hi.x() + 2 || y < lo.y() - 2 || y > hi.y() + 2) {
        ASSERT_TRUE(picture.is_background(x, y, lighting)) << x << "," << y;
      }
  std::string error;
  const auto path = std::filesystem::temp_directory_path() / "tumble-render-test.png";
  EXPECT_TRUE(write_png(path.string(), picture.rgba, kWidth, kHeight, &error)) << error;
  EXPECT_GT(std::filesystem::file_size(path), 100u);
  std::filesystem::remove(path);
}

TEST_F(RenderTest, TheLitFaceIsBrighterAndAHighlightFacesTheCamera) {
  Camera camera;
  camera.eye = {3, -4, 2.5f};
  camera.target = {0, 0, 0};
  Lighting lighting;
  lighting.towards_light = Eigen::Vector3f(0, 0, 1);  // straight above: the top face is lit
  lighting.specular = 0;
  const Picture matte = draw_cube(camera, lighting);
  auto at = [&](const Picture& picture, const Eigen::Vector3f& p) {
    const Eigen::Vector2f q = project(camera, p);
    return picture.brightness(static_cast<int>(q.x()), static_cast<int>(q.y()));
  };
  const int top = at(matte, {0, 0, 0.5f}), front = at(matte, {0, -0.5f, 0});
  EXPECT_GT(top, front + 100) << top << " vs " << front;  // front face: ambient only
  // Light from behind the camera, mirrored about the front face's normal towards the camera:
  // with specular on, the front face's centre gets brighter, and by more than elsewhere.
  const Eigen::Vector3f to_camera = (camera.eye - Eigen::Vector3f(0, -0.5f, 0)).normalized();
  const Eigen::Vector3f normal(0, -1, 0);
  lighting.towards_light = 2 * to_camera.dot(normal) * normal - to_camera;  // reflect about n
  // A dark cube, so that nothing saturates.
  lighting.specular = 0;
  lighting.shininess = 200;
  const Picture without = draw_cube(camera, lighting, 0.3f);
  lighting.specular = 0.5f;
  const Picture with = draw_cube(camera, lighting, 0.3f);
  const int gain_centre = at(with, {0, -0.5f, 0}) - at(without, {0, -0.5f, 0});
  const int gain_edge = at(with, {0.45f, -0.5f, 0.45f}) - at(without, {0.45f, -0.5f, 0.45f});
  EXPECT_GT(gain_centre, 200) << gain_centre;
  EXPECT_GT(gain_centre, gain_edge + 50) << gain_centre << " vs " << gain_edge;
}

// A hull's mesh: every facet a triangle, wound counter-clockwise about an outward normal.
TEST(HullMesh, TrianglesFaceOutward) {
  const std::vector<double> points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.2, 0.2, 0.2};
  const Mesh mesh = hull_mesh(points);  // the inner point is not a vertex
  ASSERT_EQ(mesh.indices.size(), 12u);
  const Eigen::Vector3f centroid(0.25f, 0.25f, 0.25f);
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    Eigen::Vector3f corner[3], normal;
    for (int k = 0; k < 3; ++k)
      corner[k] = Eigen::Map<const Eigen::Vector3f>(&mesh.vertices[6 * mesh.indices[t + k]]);
    normal = Eigen::Map<const Eigen::Vector3f>(&mesh.vertices[6 * mesh.indices[t] + 3]);
    EXPECT_GT(normal.dot(corner[0] - centroid), 0);
    EXPECT_GT((corner[1] - corner[0]).cross(corner[2] - corner[0]).dot(normal), 0);
  }
  EXPECT_TRUE(hull_mesh(std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}).indices.empty());
}

// A heightfield's surface: the engine's two triangles a cell, facing up, its normals those of
// the slope; a description that makes no grid gives nothing to draw.
TEST(HeightFieldMesh, TrianglesFaceUpWithTheSlopesNormals) {
  // z = 0.5 x on a 4 x 3 grid of 1 m x 2 m cells (x fastest): a plane tilted about y.
  std::vector<double> heights;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i)
      heights.push_back(0.5 * (i - 1.5));
  const Mesh mesh = height_field_mesh(4, 3, 1.0, 2.0, heights);
  ASSERT_EQ(mesh.vertices.size(), 6u * 12);
  ASSERT_EQ(mesh.indices.size(), 3u * 2 * 3 * 2);
  const Eigen::Vector3f slope_normal = Eigen::Vector3f(-0.5f, 0, 1).normalized();
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    Eigen::Vector3f corner[3];
    for (int k = 0; k < 3; ++k)
      corner[k] = Eigen::Map<const Eigen::Vector3f>(&mesh.vertices[6 * mesh.indices[t + k]]);
    const Eigen::Vector3f face = (corner[1] - corner[0]).cross(corner[2] - corner[0]).normalized();
    EXPECT_LT((face - slope_normal).norm(), 1e-6f);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f normal =
          Eigen::Map<const Eigen::Vector3f>(&mesh.vertices[6 * mesh.indices[t + k] + 3]);
      EXPECT_LT((normal - slope_normal).norm(), 1e-6f);
      EXPECT_FLOAT_EQ(corner[k].z(), 0.5f * corner[k].x());  // centred: x = i - 1.5
    }
  }
  EXPECT_TRUE(height_field_mesh(4, 3, 1.0, 2.0, std::vector<double>(11, 0.0)).indices.empty());
  EXPECT_TRUE(height_field_mesh(1, 3, 1.0, 2.0, std::vector<double>(3, 0.0)).indices.empty());
}

TEST(SurfaceMesh, EachTriangleFlatWithItsOwnNormal) {
  // A floor triangle facing up and a wall triangle facing +y, sharing an edge; one of no area.
  const std::vector<double> xyz = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 1, 2, 0, 0};
  const std::vector<std::uint32_t> indices = {0, 1, 2, 0, 3, 1, 0, 1, 4};
  const Mesh mesh = surface_mesh(xyz, indices);
  ASSERT_EQ(mesh.indices.size(), 6u);  // the one of no area left out
  ASSERT_EQ(mesh.vertices.size(), 6u * 6);
  const Eigen::Vector3f expected[2] = {{0, 0, 1}, {0, 1, 0}};
  for (std::size_t t = 0; t < 2; ++t)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f normal =
          Eigen::Map<const Eigen::Vector3f>(&mesh.vertices[6 * mesh.indices[3 * t + k] + 3]);
      EXPECT_LT((normal - expected[t]).norm(), 1e-6f) << t;
    }
  EXPECT_TRUE(surface_mesh(xyz, std::vector<std::uint32_t>{0, 1, 5}).indices.empty());
  EXPECT_TRUE(surface_mesh(std::vector<double>(4, 0.0), indices).indices.empty());
  EXPECT_TRUE(surface_mesh(xyz, std::vector<std::uint32_t>{0, 1}).indices.empty());
}

#ifdef TUMBLE_HAVE_WORLD_VIEW
// A frame's bodies become instances of their meshes; contacts add a ball and a rod each, only
// when asked.
TEST_F(RenderTest, FramesBecomeInstancesWithAnOptionalContactOverlay) {
  v1::Frame frame;
  v1::BodyDescription* box = frame.add_added();
  box->set_id(7);
  box->mutable_shape()->mutable_box()->mutable_size()->set_x(2);
  box->mutable_shape()->mutable_box()->mutable_size()->set_y(1);
  box->mutable_shape()->mutable_box()->mutable_size()->set_z(1);
  frame.add_ids(7);
  for (double v : {1.0, 2.0, 3.0})
    frame.add_positions(v);
  for (double v : {1.0, 0.0, 0.0, 0.0})
    frame.add_orientations(v);
  for (int c = 0; c < 2; ++c) {
    v1::Contacts* contacts = frame.mutable_contacts();
    contacts->add_body_a(7);
    contacts->add_body_b(7);
    for (double v : {0.0, 0.0, 0.5})
      contacts->add_points(v);
    for (double v : {0.0, 0.0, 1.0})
      contacts->add_normals(v);
    contacts->add_depths(0.01);
    contacts->add_impulses(1);
  }
  WorldView view;
  view.apply(frame);
  const auto plain = view.instances(*renderer_);
  ASSERT_EQ(plain[renderer_->box_mesh()].size(), 1u);
  EXPECT_TRUE(plain[renderer_->sphere_mesh()].empty());
  const Eigen::Matrix4f& model = plain[renderer_->box_mesh()][0].model;
  EXPECT_FLOAT_EQ(model(0, 0), 1.0f);  // half of the 2 m size: the unit cube spans [-1, 1]
  EXPECT_FLOAT_EQ(model(0, 3), 1.0f);
  EXPECT_FLOAT_EQ(model(2, 3), 3.0f);
  const auto overlay = view.contact_overlay(*renderer_);
  EXPECT_EQ(overlay[renderer_->box_mesh()].size(), 2u);  // two rods
  EXPECT_EQ(overlay[renderer_->sphere_mesh()].size(), 2u);
  // Sized to the scene: a contact ball's radius is 1.5% of the radius of the sphere around the
  // bodies (here the one box, centred at z = 3).
  const auto around = view.bounds();
  ASSERT_TRUE(around.has_value());
  EXPECT_NEAR(around->first.z(), 3.0f, 1e-5f);
  EXPECT_FLOAT_EQ(overlay[renderer_->sphere_mesh()][0].model(0, 0), 0.015f * around->second);
}

// A mesh body is drawn as its own triangles, once however many frames name it; like the ground it
// does not enlarge the sphere the camera frames.
TEST_F(RenderTest, CompoundBodiesAreDrawnPartByPart) {
  // One body: a 2 x 1 x 0.2 box 1 m above its origin and a ball of 0.5 m turned and moved 1 m
  // along x, the body at (0, 0, 3) turned a quarter about z.
  v1::Frame frame;
  v1::BodyDescription* body = frame.add_added();
  body->set_id(4);
  v1::CompoundPart* top = body->mutable_shape()->mutable_compound()->add_parts();
  v1::Vec3* size = top->mutable_shape()->mutable_box()->mutable_size();
  size->set_x(2);
  size->set_y(1);
  size->set_z(0.2);
  top->mutable_position()->set_z(1);
  v1::CompoundPart* ball = body->mutable_shape()->mutable_compound()->add_parts();
  ball->mutable_shape()->mutable_sphere()->set_radius(0.5);
  ball->mutable_position()->set_x(1);
  frame.add_ids(4);
  for (double v : {0.0, 0.0, 3.0})
    frame.add_positions(v);
  const double half = std::sqrt(0.5);
  for (double v : {half, 0.0, 0.0, half})
    frame.add_orientations(v);
  WorldView view;
  view.apply(frame);
  const auto drawn = view.instances(*renderer_);
  ASSERT_EQ(drawn[renderer_->box_mesh()].size(), 1u);
  ASSERT_EQ(drawn[renderer_->sphere_mesh()].size(), 1u);
  // The box's centre where the body's frame puts it; the ball's at +x turned to +y.
  const Eigen::Matrix4f box = drawn[renderer_->box_mesh()][0].model;
  const Eigen::Matrix4f sphere = drawn[renderer_->sphere_mesh()][0].model;
  EXPECT_LT((box.block<3, 1>(0, 3) - Eigen::Vector3f(0, 0, 4)).norm(), 1e-5f);
  EXPECT_LT((sphere.block<3, 1>(0, 3) - Eigen::Vector3f(0, 1, 3)).norm(), 1e-5f);
  // The box's long side (x in its part) along the world's y: the model's first column.
  EXPECT_LT((box.block<3, 1>(0, 0) - Eigen::Vector3f(0, 1, 0)).norm(), 1e-5f);
  EXPECT_NEAR((sphere.block<3, 1>(0, 0).norm()), 0.5f, 1e-5f);
  // Both parts share the body's colour.
  EXPECT_EQ(drawn[renderer_->box_mesh()][0].colour, drawn[renderer_->sphere_mesh()][0].colour);
  const auto around = view.bounds();
  ASSERT_TRUE(around.has_value());
  EXPECT_GE(around->second, 1.5f);  // the ball's far side is 1.5 m from the body's origin
}

TEST_F(RenderTest, MeshBodiesAreDrawnAsTheirTriangles) {
  v1::Frame frame;
  v1::BodyDescription* box = frame.add_added();
  box->set_id(7);
  v1::Vec3* size = box->mutable_shape()->mutable_box()->mutable_size();
  size->set_x(1);
  size->set_y(1);
  size->set_z(1);
  v1::BodyDescription* floor = frame.add_added();
  floor->set_id(9);
  floor->set_type(v1::BODY_TYPE_STATIC);
  v1::Mesh* mesh = floor->mutable_shape()->mutable_mesh();
  for (double v : {-50.0, -50.0, 0.0, 50.0, -50.0, 0.0, 50.0, 50.0, 0.0, -50.0, 50.0, 0.0})
    mesh->add_vertices(v);
  for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
    mesh->add_triangles(i);
  for (std::uint64_t id : {7u, 9u})
    frame.add_ids(id);
  for (double v : {0.0, 0.0, 3.0, 0.0, 0.0, 0.0})
    frame.add_positions(v);
  for (int body = 0; body < 2; ++body)
    for (double v : {1.0, 0.0, 0.0, 0.0})
      frame.add_orientations(v);
  WorldView view;
  view.apply(frame);
  view.apply(frame);
  const auto drawn = view.instances(*renderer_);
  std::size_t instances = 0, other_meshes = 0;
  for (std::size_t m = 0; m < drawn.size(); ++m) {
    instances += drawn[m].size();
    if (!drawn[m].empty() && static_cast<int>(m) != renderer_->box_mesh()) ++other_meshes;
  }
  EXPECT_EQ(instances, 2u);  // the box and the mesh
  EXPECT_EQ(drawn[renderer_->box_mesh()].size(), 1u);
  EXPECT_EQ(other_meshes, 1u);
  const auto around = view.bounds();
  ASSERT_TRUE(around.has_value());
  EXPECT_NEAR(around->first.z(), 3.0f, 1e-5f);  // the box's centre: the 100 m floor left out
  EXPECT_LT(around->second, 2.0f);
}

// A frame's joints (asked for) become a ball at each anchor and a rod along each axis; a frame
// without them draws none.
TEST_F(RenderTest, JointsBecomeAnOverlayOfAnchorsAndAxes) {
  v1::Frame frame;
  v1::BodyDescription* box = frame.add_added();
  box->set_id(7);
  box->mutable_shape()->mutable_box()->mutable_size()->set_x(1);
  box->mutable_shape()->mutable_box()->mutable_size()->set_y(1);
  box->mutable_shape()->mutable_box()->mutable_size()->set_z(1);
  frame.add_ids(7);
  for (double v : {0.0, 0.0, 3.0})
    frame.add_positions(v);
  for (double v : {1.0, 0.0, 0.0, 0.0})
    frame.add_orientations(v);
  WorldView view;
  view.apply(frame);
  EXPECT_TRUE(view.joint_overlay(*renderer_).empty());
  v1::JointStates* joints = frame.mutable_joints();
  joints->add_ids(1);
  for (double v : {0.0, 0.0, 3.5})
    joints->add_anchors(v);
  for (double v : {1.0, 0.0, 0.0})
    joints->add_axes(v);
  view.apply(frame);
  const auto overlay = view.joint_overlay(*renderer_);
  ASSERT_EQ(overlay[renderer_->sphere_mesh()].size(), 1u);
  ASSERT_EQ(overlay[renderer_->box_mesh()].size(), 1u);
  const Eigen::Matrix4f& ball = overlay[renderer_->sphere_mesh()][0].model;
  EXPECT_FLOAT_EQ(ball(2, 3), 3.5f);  // at the anchor
  // The rod's long side (the cube's z) lies along the axis, x.
  const Eigen::Matrix4f& rod = overlay[renderer_->box_mesh()][0].model;
  const Eigen::Vector3f long_side = rod.block<3, 1>(0, 2), short_side = rod.block<3, 1>(0, 0);
  EXPECT_NEAR(long_side.normalized().x(), 1.0f, 1e-5f);
  EXPECT_GT(long_side.norm(), 10 * short_side.norm());
}

// Colours follow the order bodies were described in, not their ids: a world reset gives the same
// bodies new ids, and they keep their colours. The camera frames what it sees.
TEST_F(RenderTest, ColoursSurviveAResetAndTheCameraFramesTheBodies) {
  auto describe = [](v1::Frame* frame, std::uint64_t id, double x) {
    v1::BodyDescription* d = frame->add_added();
    d->set_id(id);
    d->mutable_shape()->mutable_sphere()->set_radius(0.5);
    frame->add_ids(id);
    for (double v : {x, 0.0, 10.0})
      frame->add_positions(v);
    for (double v : {1.0, 0.0, 0.0, 0.0})
      frame->add_orientations(v);
  };
  WorldView view;
  v1::Frame first;
  for (std::uint64_t id : {1, 2, 3})
    describe(&first, id, static_cast<double>(id));
  view.apply(first);
  const auto before = view.instances(*renderer_)[renderer_->sphere_mesh()];
  v1::Frame reset;  // the same scene again, under new ids
  for (std::uint64_t id : {1, 2, 3})
    reset.add_removed(id);
  for (std::uint64_t id : {10, 11, 12})
    describe(&reset, id, static_cast<double>(id - 9));
  view.apply(reset);
  const auto after = view.instances(*renderer_)[renderer_->sphere_mesh()];
  ASSERT_EQ(before.size(), 3u);
  ASSERT_EQ(after.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_EQ(before[i].colour, after[i].colour) << i;
  EXPECT_NE(before[0].colour, before[1].colour);

  const auto around = view.bounds();
  ASSERT_TRUE(around.has_value());
  EXPECT_NEAR(around->first.x(), 2.0f, 1e-5f);
  EXPECT_NEAR(around->first.z(), 10.0f, 1e-5f);
  const Camera camera = framed(Camera(), around->first, around->second);
  EXPECT_EQ(camera.target, around->first);
  // The sphere fits the picture's height, with a margin.
  const float distance = (camera.eye - camera.target).norm();
  const float half_fov = 0.5f * camera.fov_y_degrees * static_cast<float>(M_PI) / 180;
  EXPECT_GT(distance * std::sin(half_fov), around->second);
  EXPECT_LT(distance * std::sin(half_fov), 1.2f * around->second);
}

#endif

}  // namespace
}  // namespace tumble::viewer
