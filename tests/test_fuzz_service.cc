// Issue 17: random and hostile requests for every RPC of the service, through an in-process
// channel. After each one the server answers, its own snapshot of the world restores (so nothing
// non-finite or beyond the limits got in), and a refused or read-only request left the world
// byte for byte as it was (the snapshot before and after).
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "fuzz_snapshot.h"
#include "fuzz_support.h"
#include "scene_runner.h"
#include "service.h"
#include "snapshot.h"
#include "tumble/v1/snapshot.pb.h"

namespace tumble::server {
namespace {

using testing::FuzzTally;
using testing::Hostile;

constexpr std::size_t kMaxBodies = 300;

class FuzzService {
 public:
  FuzzService()
      : host_(make_world(pile_scene(8)).value(), 1.0 / 60, 0),
        service_(host_, {.max_bodies = kMaxBodies, .token = "", .world = {}}, pile_scene(8)) {
    grpc::ServerBuilder builder;
    service_.register_on(builder);
    server_ = builder.BuildAndStart();
    stub_ = v1::World::NewStub(server_->InProcessChannel(grpc::ChannelArguments()));
  }
  ~FuzzService() {
    service_.shut_down();
    server_->Shutdown();
  }

  // Runs `count` random requests; the tally counts them and what went wrong.
  FuzzTally run(std::uint64_t seed, int count) {
    Hostile h(seed);
    FuzzTally tally;
    std::string before = snapshot();
    refresh_ids();
    for (int i = 0; i < count; ++i) {
      bool read_only = false;
      const int rpc = h.integer(0, 14);
      const grpc::Status status = send(h, rpc, &read_only);
      ++tally.tried;
      (status.ok() ? tally.accepted : tally.refused)++;
      EXPECT_NE(status.error_code(), grpc::StatusCode::INTERNAL)
          << "request " << i << " (rpc " << rpc << "): " << status.error_message();
      EXPECT_NE(status.error_code(), grpc::StatusCode::UNKNOWN) << status.error_message();
      host_.wait_idle(std::chrono::seconds(30));
      grpc::ClientContext alive;
      v1::GetInfoResponse info;
      if (!stub_->GetInfo(&alive, {}, &info).ok()) {
        ADD_FAILURE() << "the server stopped answering after request " << i;
        return tally;
      }
      const std::string after = snapshot();
      if ((!status.ok() || read_only) && after != before) {
        ++tally.half_applied;
        ADD_FAILURE() << "request " << i << " (rpc " << rpc << ", "
                      << (status.ok() ? "read only" : status.error_message())
                      << ") changed the world";
      }
      // The server's own snapshot must always restore: every value in the world is one the world
      // would accept (defect 1: a NaN made the server's own snapshot unrestorable).
      Result<SavedWorld> saved = decode_snapshot(after);
      Result<World> world = saved ? World::from_state(saved.value().settings, saved.value().state)
                                  : Result<World>(saved.status());
      if (!world) {
        ++tally.poisoned;
        ADD_FAILURE() << "after request " << i << " (rpc " << rpc
                      << ") the world's snapshot is refused: " << world.error();
        return tally;
      }
      before = after;
      if (status.ok() && !read_only) refresh_ids();
    }
    return tally;
  }

 private:
  std::string snapshot() {
    grpc::ClientContext context;
    v1::SnapshotResponse response;
    EXPECT_TRUE(stub_->Snapshot(&context, {}, &response).ok());
    return response.state();
  }
  void refresh_ids() {
    grpc::ClientContext context;
    v1::GetBodiesResponse bodies;
    EXPECT_TRUE(stub_->GetBodies(&context, {}, &bodies).ok());
    known_.clear();
    for (const auto& state : bodies.states())
      known_.push_back(state.id());
    grpc::ClientContext joints_context;
    v1::GetJointsResponse joints;
    EXPECT_TRUE(stub_->GetJoints(&joints_context, {}, &joints).ok());
    known_joints_.assign(joints.ids().begin(), joints.ids().end());
  }
  // A live joint's id most of the time; else one that names nothing.
  std::uint64_t joint_id(Hostile& h) {
    if (!known_joints_.empty() && h.chance(0.8))
      return known_joints_[static_cast<std::size_t>(h.rng().uniform() * known_joints_.size())];
    const std::uint64_t odd[] = {0, 1, 999999, UINT64_MAX};
    return odd[h.integer(0, 3)];
  }
  v1::JointSpec joint(Hostile& h) {
    v1::JointSpec spec;
    spec.set_kind(static_cast<v1::JointKind>(h.chance(0.95) ? h.integer(0, 4) : h.integer(5, 9)));
    spec.set_a(id(h));
    if (h.chance(0.6)) spec.set_b(id(h));
    set(h.vector(-5, 5), spec.mutable_anchor());
    if (h.chance(0.5)) set(h.vector(-5, 5), spec.mutable_anchor_b());
    if (h.chance(0.7)) set(h.vector(-1, 1), spec.mutable_axis());
    if (h.chance(0.3)) spec.set_length(h.number(-1, 3));
    spec.set_collide_connected(h.chance(0.2));
    if (h.chance(0.3)) {
      spec.mutable_limit()->set_lower(h.number(-4, 2));
      spec.mutable_limit()->set_upper(h.number(-2, 4));
    }
    if (h.chance(0.3)) {
      spec.mutable_motor()->set_speed(h.number(-1e4, 1e4));
      spec.mutable_motor()->set_max_force(h.number(-10, 1e6));
    }
    if (h.chance(0.3)) {
      spec.mutable_spring()->set_target(h.number(-3, 3));
      spec.mutable_spring()->set_stiffness(h.number(-1, 1e12));
      spec.mutable_spring()->set_damping(h.number(-1, 1e3));
    }
    if (h.chance(0.2)) spec.set_max_swing(h.number(-1, 4));
    if (h.chance(0.2)) spec.set_friction(h.number(-1, 50));
    return spec;
  }
  // A live id most of the time; else one that names nothing (0, stale, huge).
  std::uint64_t id(Hostile& h) {
    if (!known_.empty() && h.chance(0.8))
      return known_[static_cast<std::size_t>(h.rng().uniform() * known_.size())];
    const std::uint64_t odd[] = {
        0, 1, 999999, UINT64_MAX, std::uint64_t{1} << 53, known_.empty() ? 7 : known_.back() + 1};
    return odd[h.integer(0, 5)];
  }
  static void set(const Vec3& v, v1::Vec3* out) {
    out->set_x(v.x());
    out->set_y(v.y());
    out->set_z(v.z());
  }
  static void set(Hostile& h, v1::Quat* q) {
    if (h.chance(0.5)) {
      const Quat r = h.rng().rotation();
      q->set_w(r.w());
      q->set_x(r.x());
      q->set_y(r.y());
      q->set_z(r.z());
    } else {
      q->set_w(h.number(-1, 1));
      q->set_x(h.number(-1, 1));
      q->set_y(h.number(-1, 1));
      q->set_z(h.number(-1, 1));
    }
  }

  v1::BodySpec body(Hostile& h) {
    v1::BodySpec spec;
    v1::Shape* shape = spec.mutable_shape();
    switch (h.integer(0, 8)) {
      case 0:
        set(h.vector(0.05, 2), shape->mutable_box()->mutable_size());
        break;
      case 1:
        shape->mutable_sphere()->set_radius(h.number(0.05, 1));
        break;
      case 2:
        shape->mutable_capsule()->set_radius(h.number(0.05, 0.5));
        shape->mutable_capsule()->set_half_height(h.number(0.05, 1));
        break;
      case 3: {
        const int counts[] = {0, 2, 4, 4, 8, 12, 1025};
        const int n = counts[h.integer(0, 6)];
        const bool flat = h.chance(0.2);
        for (int p = 0; p < n; ++p) {
          Vec3 v = h.chance(0.9) ? h.rng().vector(-0.5, 0.5) : h.vector(-0.5, 0.5);
          if (flat) v.z() = 0;
          shape->mutable_hull()->add_points(v.x());
          shape->mutable_hull()->add_points(v.y());
          shape->mutable_hull()->add_points(v.z());
        }
        if (h.chance(0.1)) shape->mutable_hull()->add_points(1);  // not a whole triple
        break;
      }
      case 4:
        shape->mutable_plane();
        break;
      case 5: {
        // Terrain: sides too short, too long or fine, heights sometimes one too many.
        v1::HeightField* field = shape->mutable_heightfield();
        const std::uint32_t sides[] = {0, 1, 2, 3, 8, 9000};
        field->set_samples_x(sides[h.integer(0, 5)]);
        field->set_samples_y(sides[h.integer(0, 5)]);
        field->set_spacing_x(h.number(0.1, 1));
        field->set_spacing_y(h.number(0.1, 1));
        const int n = static_cast<int>(std::min<std::uint64_t>(
                          std::uint64_t{field->samples_x()} * field->samples_y(), 64)) +
                      (h.chance(0.2) ? 1 : 0);
        for (int k = 0; k < n; ++k)
          field->add_heights(h.number(-0.5, 0.5));
        break;
      }
      case 6: {
        // A mesh: few or no vertices, indices in range or past it, repeated (degenerate), or
        // not a whole triple.
        v1::Mesh* mesh = shape->mutable_mesh();
        const int counts[] = {0, 3, 4, 8, 20};
        const int n = counts[h.integer(0, 4)];
        for (int p = 0; p < n; ++p) {
          const Vec3 v = h.chance(0.9) ? h.rng().vector(-2, 2) : h.vector(-2, 2);
          for (int k = 0; k < 3; ++k)
            mesh->add_vertices(v[k]);
        }
        const int triangles = h.integer(0, 12);
        for (int t = 0; t < 3 * triangles; ++t)
          mesh->add_triangles(
              static_cast<std::uint32_t>(h.integer(0, n + (h.chance(0.05) ? 3 : 0))));
        if (h.chance(0.1)) mesh->add_triangles(0);
        break;
      }
      case 7: {
        // A compound: no parts or several, each a box or ball (now and then a plane, a compound
        // or nothing), at offsets sometimes hostile, turned sometimes by no unit quaternion.
        v1::Compound* compound = shape->mutable_compound();
        for (int p = h.integer(0, 5); p > 0; --p) {
          v1::CompoundPart* part = compound->add_parts();
          const double kind = h.rng().uniform();
          if (kind < 0.45)
            set(h.vector(0.05, 1), part->mutable_shape()->mutable_box()->mutable_size());
          else if (kind < 0.9)
            part->mutable_shape()->mutable_sphere()->set_radius(h.number(0.05, 0.5));
          else if (kind < 0.94)
            part->mutable_shape()->mutable_plane();
          else if (kind < 0.97)
            part->mutable_shape()->mutable_compound()->add_parts();
          set(h.chance(0.9) ? h.rng().vector(-1, 1) : h.vector(-1, 1), part->mutable_position());
          if (h.chance(0.3)) set(h, part->mutable_orientation());
        }
        break;
      }
      default:
        if (h.chance(0.5)) shape->mutable_sphere()->set_radius(0.2);
        break;  // or no shape at all
    }
    if (h.chance(0.15)) spec.set_type(v1::BODY_TYPE_STATIC);
    if (h.chance(0.1)) spec.set_type(v1::BODY_TYPE_KINEMATIC);
    if (h.chance(0.05)) spec.set_type(static_cast<v1::BodyType>(h.integer(2, 9)));
    if (h.chance(0.7)) set(h.vector(-5, 5), spec.mutable_position());
    if (h.chance(0.3)) set(h, spec.mutable_orientation());
    if (h.chance(0.4)) set(h.vector(-10, 10), spec.mutable_linear_velocity());
    if (h.chance(0.4)) set(h.vector(-10, 10), spec.mutable_angular_velocity());
    if (h.chance(0.3)) spec.set_mass(h.number(0.1, 10));
    if (h.chance(0.2)) spec.set_density(h.number(100, 5000));
    if (h.chance(0.2)) spec.set_friction(h.number(0, 1));
    if (h.chance(0.2)) spec.set_restitution(h.number(0, 1));
    if (h.chance(0.1)) spec.set_gravity_scale(h.number(-2, 2));
    if (h.chance(0.1)) spec.set_linear_damping(h.number(0, 10));
    if (h.chance(0.1)) spec.set_angular_damping(h.number(0, 10));
    if (h.chance(0.1)) set(h.vector(-100, 100), spec.mutable_force());
    if (h.chance(0.1)) set(h.vector(-10, 10), spec.mutable_torque());
    if (h.chance(0.1)) spec.set_collision_layers(h.integer(0, 7));
    if (h.chance(0.1)) spec.set_collision_mask(h.integer(0, 7));
    spec.set_color(static_cast<std::uint32_t>(h.rng().uniform() * 4294967295.0));
    return spec;
  }

  // Sends one random request of kind `rpc`; `read_only` says it may not change the world.
  grpc::Status send(Hostile& h, int rpc, bool* read_only) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    switch (rpc) {
      case 0: {
        v1::SpawnBodiesRequest request;
        const int sizes[] = {0, 1, 1, 2, 3, 5, 40, 400};
        for (int n = sizes[h.integer(0, 7)]; n > 0; --n)
          *request.add_bodies() = body(h);
        v1::SpawnBodiesResponse response;
        return stub_->SpawnBodies(&context, request, &response);
      }
      case 1: {
        v1::RemoveBodiesRequest request;
        for (int n = h.chance(0.02) ? 5000 : h.integer(0, 3); n > 0; --n)
          request.add_ids(id(h));
        v1::RemoveBodiesResponse response;
        return stub_->RemoveBodies(&context, request, &response);
      }
      case 2: {
        v1::SetBodyStateRequest request;
        for (int n = h.integer(0, 4); n > 0; --n) {
          v1::BodyStateUpdate* u = request.add_updates();
          u->set_id(id(h));
          if (h.chance(0.5)) set(h.vector(-5, 5), u->mutable_position());
          if (h.chance(0.3)) set(h, u->mutable_orientation());
          if (h.chance(0.4)) set(h.vector(-10, 10), u->mutable_linear_velocity());
          if (h.chance(0.4)) set(h.vector(-10, 10), u->mutable_angular_velocity());
          if (h.chance(0.2)) set(h.vector(-100, 100), u->mutable_force());
          if (h.chance(0.1)) set(h.vector(-10, 10), u->mutable_torque());
          if (h.chance(0.1)) set(h.vector(-5, 5), u->mutable_force_point());
          if (h.chance(0.1)) u->set_gravity_scale(h.number(-2, 2));
          if (h.chance(0.1)) u->set_linear_damping(h.number(0, 10));
          if (h.chance(0.1)) u->set_angular_damping(h.number(0, 10));
          if (h.chance(0.1)) u->set_collision_layers(h.integer(0, 7));
          if (h.chance(0.1)) u->set_collision_mask(h.integer(0, 7));
        }
        v1::SetBodyStateResponse response;
        return stub_->SetBodyState(&context, request, &response);
      }
      case 3: {
        v1::ApplyImpulseRequest request;
        if (h.chance(0.2)) {
          // Issue 31: several impulses on one body, each within the speed limit alone and their
          // sum perhaps not; all or nothing.
          const std::uint64_t target = id(h);
          for (int n = h.integer(2, 10); n > 0; --n) {
            v1::Impulse* i = request.add_impulses();
            i->set_id(target);
            set(h.vector(-1, 1) * std::pow(10.0, h.integer(2, 6)), i->mutable_impulse());
          }
        }
        for (int n = h.integer(0, 3); n > 0; --n) {
          v1::Impulse* i = request.add_impulses();
          i->set_id(id(h));
          set(h.vector(-10, 10), i->mutable_impulse());
          if (h.chance(0.5)) set(h.vector(-5, 5), i->mutable_point());
        }
        v1::ApplyImpulseResponse response;
        return stub_->ApplyImpulse(&context, request, &response);
      }
      case 4: {
        *read_only = true;
        v1::GetBodiesRequest request;
        for (int n = h.integer(0, 3); n > 0; --n)
          request.add_ids(id(h));
        if (h.chance(0.1))  // issue 31: one id many times, once a reply of millions
          for (int n = h.integer(2, 2000), same = request.ids_size() > 0; n > 0; --n)
            request.add_ids(same ? request.ids(0) : id(h));
        v1::GetBodiesResponse response;
        return stub_->GetBodies(&context, request, &response);
      }
      case 5: {
        v1::LoadSceneRequest request;
        if (h.chance(0.5)) {
          const char* builtins[] = {"pile:6",   "pyramid:3", "tower:4",          "pyramid:100000",
                                    "pile:0",   "pile:-3",   "pile:99999999999", "tower:x",
                                    "",         "bogus",     "spin:3",           "default",
                                    "pile:300", "pile"};
          request.set_builtin(builtins[h.integer(0, 13)]);
          if (h.chance(0.05)) request.set_builtin(std::string(100000, 'p'));  // echoed? clipped
        } else if (h.chance(0.9)) {
          request.set_scene_json(h.mutate(std::string(default_scene_json())));
        }
        v1::LoadSceneResponse response;
        return stub_->LoadScene(&context, request, &response);
      }
      case 6: {
        v1::ControlRequest request;
        v1::RunSettings* s = request.mutable_settings();
        if (h.chance(0.2)) s->set_dt(h.number(1e-3, 0.05));
        if (h.chance(0.1)) s->set_substeps(h.chance(0.8) ? h.integer(-2, 12) : 1000000);
        if (h.chance(0.2)) s->set_solver(static_cast<v1::SolverKind>(h.integer(0, 6)));
        if (h.chance(0.2)) set(h.vector(-20, 20), s->mutable_gravity());
        if (h.chance(0.1)) s->set_real_time_factor(h.number(0, 2));
        if (h.chance(0.1)) s->set_iterations(h.chance(0.8) ? h.integer(-2, 40) : 1000000);
        if (h.chance(0.1))
          s->set_joint_position_passes(h.chance(0.8) ? h.integer(-2, 12) : 1000000);
        switch (h.integer(0, 3)) {
          case 0:
            request.set_step(static_cast<std::uint32_t>(h.integer(1, 3)));
            break;
          case 1:
            request.set_pause(true);
            break;
          case 2:
            request.set_reset(h.chance(0.3));
            break;
          default:
            break;
        }
        v1::ControlResponse response;
        return stub_->Control(&context, request, &response);
      }
      case 7: {
        *read_only = true;
        v1::SnapshotResponse response;
        return stub_->Snapshot(&context, {}, &response);
      }
      case 8: {
        v1::RestoreRequest request;
        request.set_state(damaged_snapshot(h));
        v1::RestoreResponse response;
        return stub_->Restore(&context, request, &response);
      }
      case 10: {
        v1::CreateJointsRequest request;
        const int sizes[] = {0, 1, 1, 2, 3, 10, 700};
        for (int n = sizes[h.integer(0, 6)]; n > 0; --n)
          *request.add_joints() = joint(h);
        v1::CreateJointsResponse response;
        return stub_->CreateJoints(&context, request, &response);
      }
      case 11: {
        v1::RemoveJointsRequest request;
        for (int n = h.integer(0, 3); n > 0; --n)
          request.add_ids(joint_id(h));
        v1::RemoveJointsResponse response;
        return stub_->RemoveJoints(&context, request, &response);
      }
      case 12: {
        v1::SetJointDrivesRequest request;
        for (int n = h.integer(0, 3); n > 0; --n) {
          v1::JointDriveUpdate* u = request.add_updates();
          u->set_id(joint_id(h));
          if (h.chance(0.5)) *u->mutable_motor() = joint(h).motor();
          if (h.chance(0.5)) *u->mutable_spring() = joint(h).spring();
          u->set_motor_off(h.chance(0.1));
          u->set_spring_off(h.chance(0.1));
        }
        v1::SetJointDrivesResponse response;
        return stub_->SetJointDrives(&context, request, &response);
      }
      case 13: {
        *read_only = true;
        v1::GetJointsRequest request;
        for (int n = h.integer(0, 3); n > 0; --n)
          request.add_ids(joint_id(h));
        v1::GetJointsResponse response;
        return stub_->GetJoints(&context, request, &response);
      }
      case 14: {
        *read_only = true;
        v1::QueryRequest request;
        const int rays = h.chance(0.05) ? 300000 : h.integer(0, 5);
        for (int n = 3 * rays + (h.chance(0.05) ? 1 : 0); n > 0; --n)
          request.add_ray_origins(h.number(-10, 10));
        for (int n = 3 * rays + (h.chance(0.05) ? 2 : 0); n > 0; --n)
          request.add_ray_directions(h.number(-1, 1));
        for (int n = h.integer(0, 2); n > 0; --n)
          request.add_ray_max_distances(h.number(0, 100));
        if (h.chance(0.3)) request.set_ray_mask(h.integer(0, 7));
        if (h.chance(0.3)) request.set_hits_per_ray(h.chance(0.1) ? 1000 : h.integer(0, 8));
        for (int n = h.chance(0.02) ? 300 : h.integer(0, 2); n > 0; --n) {
          v1::OverlapQuery* overlap = request.add_overlaps();
          const v1::BodySpec spec = body(h);  // its shape, position and orientation
          *overlap->mutable_shape() = spec.shape();
          *overlap->mutable_position() = spec.position();
          if (spec.has_orientation()) *overlap->mutable_orientation() = spec.orientation();
          if (h.chance(0.2)) overlap->set_mask(h.integer(0, 7));
        }
        for (int n = h.chance(0.02) ? 70000 : h.integer(0, 2); n > 0; --n) {
          v1::ClosestPointQuery* closest = request.add_closest_points();
          closest->set_id(id(h));
          set(h.vector(-10, 10), closest->mutable_point());
          if (h.chance(0.5)) closest->set_max_distance(h.number(0, 100));
        }
        for (int n = h.chance(0.02) ? 1100 : h.integer(0, 2); n > 0; --n) {
          v1::ShapeCastQuery* cast = request.add_shape_casts();
          const v1::BodySpec spec = body(h);
          *cast->mutable_shape() = spec.shape();
          *cast->mutable_position() = spec.position();
          if (spec.has_orientation()) *cast->mutable_orientation() = spec.orientation();
          const double reach = h.chance(0.05) ? 1e12 : h.chance(0.05) ? NAN : 20.0;
          set(h.vector(-reach, reach), cast->mutable_translation());
          if (h.chance(0.2)) cast->set_mask(h.integer(0, 7));
        }
        v1::QueryResponse response;
        return stub_->Query(&context, request, &response);
      }
      default: {
        *read_only = true;
        v1::StreamFramesRequest request;
        request.set_max_rate(h.chance(0.1) ? std::pow(10.0, -h.integer(3, 300)) : h.number(0, 100));
        request.set_velocities(h.chance(0.5));
        request.set_contacts(h.chance(0.5));
        request.set_stats(h.chance(0.5));
        for (int n = h.integer(0, 2); n > 0; --n)
          request.add_ids(id(h));
        context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(15));
        auto reader = stub_->StreamFrames(&context, request);
        v1::Frame frame;
        while (reader->Read(&frame)) {
        }
        const grpc::Status status = reader->Finish();
        // A stream cut by its deadline is how this client ends it, not a refusal.
        return status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED ? grpc::Status::OK
                                                                          : status;
      }
    }
  }

  // This server's snapshot, damaged (one in ten left whole, to be restored).
  std::string damaged_snapshot(Hostile& h) {
    const std::string good = snapshot();
    return h.chance(0.1) ? good : testing::damaged_snapshot(h, good);
  }

  WorldHost host_;
  WorldService service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<v1::World::Stub> stub_;
  std::vector<std::uint64_t> known_, known_joints_;
};

TEST(FuzzService, EveryRpcSurvivesHostileRequestsAndRefusalsChangeNothing) {
  FuzzService fuzz;
  const FuzzTally tally = fuzz.run(20261123, 2500);
  std::printf(
      "fuzz service: %llu requests, %llu accepted, %llu refused, %llu half-applied, %llu "
      "poisoned the world\n",
      static_cast<unsigned long long>(tally.tried), static_cast<unsigned long long>(tally.accepted),
      static_cast<unsigned long long>(tally.refused),
      static_cast<unsigned long long>(tally.half_applied),
      static_cast<unsigned long long>(tally.poisoned));
  EXPECT_EQ(tally.tried, 2500u);
  EXPECT_EQ(tally.half_applied, 0u);
  EXPECT_EQ(tally.poisoned, 0u);
  // Both kinds must be common, or the suite tests little.
  EXPECT_GT(tally.accepted, 500u);
  EXPECT_GT(tally.refused, 500u);
}

}  // namespace
}  // namespace tumble::server
