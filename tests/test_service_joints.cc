// Joints through the gRPC service (CreateJoints, RemoveJoints, SetJointDrives, GetJoints):
// batches all or nothing with the entry and field named, motors driven while the world runs,
// joints gone with their bodies, and joints carried through snapshots.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "scene_runner.h"
#include "service.h"

namespace tumble::server {
namespace {

class JointServiceTest : public ::testing::Test {
 protected:
  JointServiceTest()
      : host_(make_world(pile_scene(2)).value(), 1.0 / 60, 0),
        service_(host_, {.max_bodies = 10, .token = "", .world = {}}, pile_scene(2)) {
    grpc::ServerBuilder builder;
    service_.register_on(builder);
    server_ = builder.BuildAndStart();
    stub_ = v1::World::NewStub(server_->InProcessChannel(grpc::ChannelArguments()));
  }
  ~JointServiceTest() override {
    service_.shut_down();
    server_->Shutdown();
  }

  // A plate in the air, 1 kg: its id.
  std::uint64_t spawn_plate(double x) {
    v1::SpawnBodiesRequest request;
    v1::BodySpec* spec = request.add_bodies();
    spec->mutable_shape()->mutable_box()->mutable_size()->set_x(1);
    spec->mutable_shape()->mutable_box()->mutable_size()->set_y(1);
    spec->mutable_shape()->mutable_box()->mutable_size()->set_z(0.2);
    spec->mutable_position()->set_x(x);
    spec->mutable_position()->set_z(20);
    spec->set_mass(1);
    grpc::ClientContext context;
    v1::SpawnBodiesResponse response;
    EXPECT_TRUE(stub_->SpawnBodies(&context, request, &response).ok());
    return response.ids(0);
  }

  // A hinge about z through the plate's centre, to the world, with a motor.
  static v1::JointSpec motor_hinge(std::uint64_t plate, double x, double speed) {
    v1::JointSpec spec;
    spec.set_kind(v1::JOINT_KIND_HINGE);
    spec.set_a(plate);
    spec.mutable_anchor()->set_x(x);
    spec.mutable_anchor()->set_z(20);
    spec.mutable_axis()->set_z(1);
    spec.mutable_motor()->set_speed(speed);
    spec.mutable_motor()->set_max_force(100);
    return spec;
  }

  grpc::Status create(const v1::CreateJointsRequest& request, v1::CreateJointsResponse* out) {
    grpc::ClientContext context;
    return stub_->CreateJoints(&context, request, out);
  }
  v1::GetJointsResponse joints(const std::vector<std::uint64_t>& ids = {}) {
    v1::GetJointsRequest request;
    for (std::uint64_t id : ids)
      request.add_ids(id);
    grpc::ClientContext context;
    v1::GetJointsResponse response;
    EXPECT_TRUE(stub_->GetJoints(&context, request, &response).ok());
    return response;
  }
  std::uint32_t joint_count() {
    grpc::ClientContext context;
    v1::GetInfoResponse info;
    EXPECT_TRUE(stub_->GetInfo(&context, {}, &info).ok());
    return info.joint_count();
  }
  void step(std::uint32_t steps) {
    v1::ControlRequest request;
    request.set_step(steps);
    grpc::ClientContext context;
    v1::ControlResponse response;
    ASSERT_TRUE(stub_->Control(&context, request, &response).ok());
    host_.wait_idle(std::chrono::seconds(30));
  }

  WorldHost host_;
  WorldService service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<v1::World::Stub> stub_;
};

TEST_F(JointServiceTest, CreateDriveReadAndRemove) {
  const std::uint64_t plate = spawn_plate(0);
  v1::CreateJointsRequest request;
  *request.add_joints() = motor_hinge(plate, 0, 2);
  v1::CreateJointsResponse created;
  ASSERT_TRUE(create(request, &created).ok());
  ASSERT_EQ(created.ids_size(), 1);
  EXPECT_EQ(joint_count(), 1u);
  step(60);
  v1::GetJointsResponse read = joints();
  ASSERT_EQ(read.ids_size(), 1);
  EXPECT_EQ(read.ids(0), created.ids(0));
  EXPECT_EQ(read.specs(0).kind(), v1::JOINT_KIND_HINGE);
  EXPECT_EQ(read.specs(0).a(), plate);
  EXPECT_EQ(read.specs(0).b(), 0u);
  EXPECT_EQ(read.specs(0).motor().speed(), 2);
  EXPECT_NEAR(read.states(0).speed(), 2, 1e-9);
  EXPECT_LT(read.states(0).error(), 1e-6);
  // The plate hangs on the hinge: the joint carries its weight.
  EXPECT_NEAR(std::abs(read.states(0).force().z()), 9.81, 0.01);

  v1::SetJointDrivesRequest drive;
  v1::JointDriveUpdate* update = drive.add_updates();
  update->set_id(created.ids(0));
  update->mutable_motor()->set_speed(-3);
  update->mutable_motor()->set_max_force(100);
  grpc::ClientContext drive_context;
  v1::SetJointDrivesResponse driven;
  ASSERT_TRUE(stub_->SetJointDrives(&drive_context, drive, &driven).ok());
  step(30);
  EXPECT_NEAR(joints({created.ids(0)}).states(0).speed(), -3, 1e-9);

  v1::RemoveJointsRequest remove;
  remove.add_ids(created.ids(0));
  grpc::ClientContext remove_context;
  v1::RemoveJointsResponse removed;
  ASSERT_TRUE(stub_->RemoveJoints(&remove_context, remove, &removed).ok());
  EXPECT_EQ(joint_count(), 0u);
  // Its id names nothing now.
  v1::GetJointsRequest stale;
  stale.add_ids(created.ids(0));
  grpc::ClientContext stale_context;
  v1::GetJointsResponse none;
  EXPECT_EQ(stub_->GetJoints(&stale_context, stale, &none).error_code(),
            grpc::StatusCode::NOT_FOUND);
}

TEST_F(JointServiceTest, BadBatchesAreRefusedByEntryAndFieldAndChangeNothing) {
  const std::uint64_t plate = spawn_plate(0);
  auto refused = [&](const v1::CreateJointsRequest& request, grpc::StatusCode code,
                     const std::string& field) {
    v1::CreateJointsResponse response;
    const grpc::Status status = create(request, &response);
    EXPECT_EQ(status.error_code(), code) << status.error_message();
    EXPECT_EQ(status.error_message().rfind(field, 0), 0u) << status.error_message();
    EXPECT_EQ(joint_count(), 0u);
  };
  v1::CreateJointsRequest request;
  *request.add_joints() = motor_hinge(plate, 0, 1);
  *request.add_joints() = motor_hinge(plate, 0, 1);
  request.mutable_joints(1)->mutable_axis()->set_z(0);
  refused(request, grpc::StatusCode::INVALID_ARGUMENT, "joints[1].axis: must not be zero");
  request.mutable_joints(1)->mutable_axis()->set_z(1);
  request.mutable_joints(1)->set_a(999999);
  refused(request, grpc::StatusCode::NOT_FOUND, "joints[1].a: no body 999999");
  request.mutable_joints(1)->set_a(plate);
  request.mutable_joints(1)->set_kind(v1::JOINT_KIND_BALL);
  refused(request, grpc::StatusCode::INVALID_ARGUMENT, "joints[1].motor:");
  request.mutable_joints(1)->set_kind(static_cast<v1::JointKind>(9));
  refused(request, grpc::StatusCode::INVALID_ARGUMENT, "joints[1].kind:");
  // Two joints a body: a server for 10 bodies holds at most 20.
  v1::CreateJointsRequest many;
  for (int i = 0; i < 21; ++i)
    *many.add_joints() = motor_hinge(plate, 0, 1);
  refused(many, grpc::StatusCode::RESOURCE_EXHAUSTED, "request: joints: more than 20 entries");

  v1::CreateJointsRequest good;
  *good.add_joints() = motor_hinge(plate, 0, 1);
  v1::CreateJointsResponse created;
  ASSERT_TRUE(create(good, &created).ok());
  many.mutable_joints()->RemoveLast();  // 20, each allowed alone: with the one made, too many
  v1::CreateJointsResponse none;
  const grpc::Status full = create(many, &none);
  EXPECT_EQ(full.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(full.error_message(), "joints: 20 more would exceed the 20 joints allowed");
  EXPECT_EQ(joint_count(), 1u);
  {  // a motor where the kind has none, an unknown joint: the batch changes nothing
    v1::SetJointDrivesRequest drive;
    drive.add_updates()->set_id(created.ids(0));
    drive.mutable_updates(0)->mutable_motor()->set_speed(5);
    drive.mutable_updates(0)->mutable_motor()->set_max_force(-1);
    grpc::ClientContext context;
    v1::SetJointDrivesResponse response;
    const grpc::Status status = stub_->SetJointDrives(&context, drive, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(status.error_message().rfind("updates[0].motor.max_force:", 0), 0u)
        << status.error_message();
    EXPECT_EQ(joints().specs(0).motor().speed(), 1);
  }
  {
    v1::RemoveJointsRequest remove;
    remove.add_ids(created.ids(0));
    remove.add_ids(12345);
    grpc::ClientContext context;
    v1::RemoveJointsResponse response;
    const grpc::Status status = stub_->RemoveJoints(&context, remove, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
    EXPECT_EQ(status.error_message().rfind("ids[1]: no joint 12345", 0), 0u);
    EXPECT_EQ(joint_count(), 1u);
  }
  // Removing the body removes its joint, and the joint's id with it.
  v1::RemoveBodiesRequest remove_body;
  remove_body.add_ids(plate);
  grpc::ClientContext context;
  v1::RemoveBodiesResponse removed;
  ASSERT_TRUE(stub_->RemoveBodies(&context, remove_body, &removed).ok());
  EXPECT_EQ(joint_count(), 0u);
  EXPECT_EQ(joints().ids_size(), 0);
}

TEST_F(JointServiceTest, JointsComeBackFromASnapshot) {
  const std::uint64_t plate = spawn_plate(0);
  v1::CreateJointsRequest request;
  *request.add_joints() = motor_hinge(plate, 0, 2);
  v1::CreateJointsResponse created;
  ASSERT_TRUE(create(request, &created).ok());
  step(10);
  grpc::ClientContext snap_context;
  v1::SnapshotResponse snapshot;
  ASSERT_TRUE(stub_->Snapshot(&snap_context, {}, &snapshot).ok());
  v1::RemoveJointsRequest remove;
  remove.add_ids(created.ids(0));
  grpc::ClientContext remove_context;
  v1::RemoveJointsResponse removed;
  ASSERT_TRUE(stub_->RemoveJoints(&remove_context, remove, &removed).ok());
  v1::RestoreRequest restore;
  restore.set_state(snapshot.state());
  grpc::ClientContext restore_context;
  v1::RestoreResponse restored;
  ASSERT_TRUE(stub_->Restore(&restore_context, restore, &restored).ok());
  const v1::GetJointsResponse read = joints();
  ASSERT_EQ(read.ids_size(), 1);
  EXPECT_EQ(read.ids(0), created.ids(0));  // a snapshot of this server: the joint's own id
  EXPECT_EQ(read.specs(0).motor().speed(), 2);
  EXPECT_NEAR(read.states(0).speed(), 2, 1e-9);
}

}  // namespace
}  // namespace tumble::server
