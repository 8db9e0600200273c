// The world: owns bodies, finds which of them touch, and steps them.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "physics/body.h"
#include "physics/body_view.h"
#include "physics/collision.h"
#include "physics/joint.h"
#include "physics/query.h"
#include "physics/limits.h"
#include "physics/math.h"
#include "physics/status.h"
#include "physics/step.h"

namespace tumble {

enum class BroadPhaseMethod : std::uint8_t {
  kAuto,           // the world chooses (sweep-and-prune for few bodies, the grid otherwise)
  kHashGrid,       // hierarchical hashed uniform grids, built in parallel
  kSweepAndPrune,  // sort on x, sweep
};

struct WorldSettings {
  Vec3 gravity = Vec3(0, 0, -9.81);  // m/s^2
  int threads = 0;                   // OpenMP threads for the step; 0 = OpenMP's default
  BroadPhaseMethod broad_phase = BroadPhaseMethod::kAuto;
  CollisionSettings collision;
  SolverSettings solver;
  WorldLimits limits;
};

// Checks settings without applying them; the message names the field.
Status validate(const WorldSettings& settings);

// A pair of bodies whose bounding boxes overlap; `a` < `b` by body index.
struct BodyPair {
  std::uint32_t a, b;
  auto operator<=>(const BodyPair&) const = default;
};

struct Contact {
  BodyId a, b;
  ContactManifold manifold;
};

// A change of a body's pose or velocities; absent fields stay as they are.
// What World::set_motion changes of a body: the fields given, the rest as they were.
struct BodyMotion {
  std::optional<Vec3> position;  // m, centre of mass
  std::optional<Quat> orientation;
  std::optional<Vec3> linear_velocity;   // m/s
  std::optional<Vec3> angular_velocity;  // rad/s, world
  // The held force (N, world) and torque (N m, world, about the centre of mass: BodyDef). With
  // `force_point` (m, world, where the body is now) the force acts there: the held torque becomes
  // (point - centre) x force plus `torque` (0 when not given). A point needs a force.
  std::optional<Vec3> force;
  std::optional<Vec3> torque;
  std::optional<Vec3> force_point;
  std::optional<double> gravity_scale;
  std::optional<double> linear_damping, angular_damping;  // 1/s
  std::optional<CollisionFilter> filter;  // wakes what the body touches
};

// One impulse of a batch (World::apply_impulses).
struct ImpulseAt {
  BodyId body;
  Vec3 impulse = Vec3::Zero();  // N s, world
  std::optional<Vec3> point;    // m, world; the centre of mass when empty
};

struct StepScratch;
struct Joint;
class QueryIndex;
struct JointSlot;

// What happened to a body since the world's events were last cleared (World::body_events): the
// bits of BodyEvent::flags.
enum BodyEventFlag : std::uint8_t {
  kBodyAdded = 1,
  kBodyRemoved = 2,
  kBodyMoved = 4,  // pose or velocities changed: by a step, set_motion or an impulse
  kBodyWoke = 8,
  kBodyFellAsleep = 16,
};
struct BodyEvent {
  BodyId body;
  std::uint8_t flags = 0;
};

// The sizes in the header of a saved state (World::state_sizes).
struct StateSizes {
  std::uint64_t bytes = 0;
  std::uint32_t slots = 0;  // body slots, live or free
  std::uint32_t free_slots = 0;
  std::uint32_t contact_pairs = 0;
};

class World {
 public:
  explicit World(const WorldSettings& settings = {});
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;

  // Creates one body, or none and says why (an invalid definition, or one beyond the limits).
  Result<BodyId> create_body(const BodyDef& def);
  // Creates all bodies or none; a failure names the definition ("bodies[3].mass: must be > 0").
  Result<std::vector<BodyId>> create_bodies(std::span<const BodyDef> defs);
  // Removes a body; sleeping bodies that may have rested on it wake.
  Status remove_body(BodyId id);
  // Wakes a sleeping body and the island it fell asleep with.
  Status wake(BodyId id);
  // Moves a body or changes its velocities (the fields given; a static body takes a pose only).
  // Refused, changing nothing, for an unknown id, a value beyond the world's limits or a
  // quaternion not within 1e-3 of unit length; check_motion says so without changing anything. The
  // body wakes, and so do sleepers around a static body that moved.
  Status check_motion(BodyId id, const BodyMotion& motion) const;
  Status set_motion(BodyId id, const BodyMotion& motion);
  // An impulse (N s, world) at a point (m, world; the centre of mass when null) of a dynamic
  // body, applied now to its velocities; the body wakes. Refused when the velocities it gives
  // would be beyond the world's limits.
  Status check_impulse(BodyId id, const Vec3& impulse, const Vec3* point) const;
  Status apply_impulse(BodyId id, const Vec3& impulse, const Vec3* point);
  // Impulses applied in order, all or nothing. Several on one body add up: each is checked with
  // those before it on the same body, so the velocities the body ends with are within the limits.
  // The message names the entry ("[3].impulse: ...").
  Status apply_impulses(std::span<const ImpulseAt> impulses);

  // Joints (joint.h) between two bodies of this world, or a body and the world: made from a
  // definition in world coordinates at the bodies' present poses, or refused naming the field
  // ("b: no body with this id"). Both bodies wake. Removing a body removes its joints.
  static constexpr std::size_t kMaxJoints = 1 << 20;
  Result<JointId> create_joint(const JointDef& def);
  // What create_joint would answer, without making the joint.
  Status check_joint(const JointDef& def) const;
  Status remove_joint(JointId id);
  bool contains(JointId id) const;
  std::size_t joint_count() const { return joint_count_; }
  // How far the joint is from holding at the bodies' present poses: m for its anchors (or its
  // length), rad for its axes or rotation, whichever is larger.
  Result<double> joint_error(JointId id) const;
  // A running joint's motor or spring (joint.h), changed for the coming steps (its bodies wake),
  // or refused naming the field ("motor: only hinges and sliders have one").
  Status set_joint_motor(JointId id, const JointMotor& motor);
  Status set_joint_spring(JointId id, const JointSpring& spring);
  // The joint's coordinate, its rate and the reaction it gave over the last step (joint.h).
  Result<JointReading> joint_reading(JointId id) const;
  // The joint's definition as it stands: anchors and axis where the bodies now carry them (a
  // distance joint's anchor_b, a world anchor, where made), its limit, motor and spring now.
  Result<JointDef> joint_def(JointId id) const;
  // Joints by slot, as bodies are (slot_count, id_at): the id at a slot, invalid if none.
  std::uint32_t joint_slot_count() const;
  JointId joint_at(std::uint32_t slot) const;

  // The whole state (settings apart: settings()) as bytes in the engine's own versioned format
  // (docs/STATE_FORMAT.md): a world made from them steps on exactly as this one would, bit for bit.
  // from_state checks everything (the bytes may come from a file or the network) and names what
  // is wrong; bytes of another format version are refused with a message naming both versions.
  // restore_state replaces this world's bodies, contacts and clock, keeping its settings, and
  // changes nothing when it fails.
  static constexpr std::uint32_t kStateFormatVersion = 2;
  std::string save_state() const;
  // What saved bytes hold, from their header alone (checked as from_state checks it), so that a
  // caller can bound what restoring them would cost before paying it.
  static Result<StateSizes> state_sizes(std::string_view bytes);
  static Result<World> from_state(const WorldSettings& settings, std::string_view bytes);
  Status restore_state(std::string_view bytes);

  bool contains(BodyId id) const;
  // A look at the body, false when `id` is stale or was never made.
  BodyView body(BodyId id) const;
  BodyId id_at(std::uint32_t index) const;  // the live body in slot `index`, or an invalid id
  std::size_t body_count() const { return live_count_; }
  std::uint32_t slot_count() const;

  const WorldSettings& settings() const { return settings_; }
  // Applies all settings or none: new limits are refused while a body lies beyond them.
  Status set_settings(const WorldSettings& settings);
  void set_broad_phase(BroadPhaseMethod method) { settings_.broad_phase = method; }

  // Advances the world by dt seconds (> 0, at most limits.max_time_step): broad phase, narrow
  // phase, contact preparation, solve and integrate per island, position correction. See StepStats
  // for what it reports; a body the step would take beyond the limits is held within them and
  // counted there.
  Status step(double dt);
  const StepStats& last_step() const { return stats_; }
  // The most pairs a step considers: kPairsPerBody per body and kMinPairBound more. A dense pile
  // has fewer than 8 per body; only bodies heaped inside one another reach it, and then the pairs
  // first in (slot, slot) order are kept, the same for any thread count, and the step counts it
  // in StepStats::pair_limit_hits. It bounds the memory and time of every stage after the broad
  // phase.
  static constexpr std::size_t kPairsPerBody = 32, kMinPairBound = 1 << 16;
  std::size_t max_pairs() const;
  double time() const { return time_; }  // s, simulated
  std::uint64_t step_count() const { return stats_.step; }
  // Normal impulse (N s) of each contact point over the whole last step (all substeps of the soft
  // solver), in the order of contacts()'s manifolds and their points.
  std::span<const double> contact_impulses() const { return impulses_; }
  // The manifolds of the last step (or of the last find_contacts()).
  std::span<const Contact> contacts() const { return contacts_; }
  // The manifolds of the islands now asleep, as the step before they fell asleep left them: a
  // box asleep on the floor still rests on it. With the normal force (N) each point carried
  // then, in the order of the manifolds and their points; times a step's dt, the impulse it
  // would carry in that step. Dropped when the island wakes. Not part of save_state(): a world
  // made by from_state() lists its sleepers' contacts again once they wake and settle.
  std::span<const Contact> resting_contacts() const { return resting_contacts_; }
  std::span<const double> resting_contact_forces() const { return resting_forces_; }
  // Changes whenever the two lists above do (islands falling asleep or waking): a caller that
  // copies them (the server's frames) copies again only then.
  std::uint64_t resting_contacts_version() const { return resting_contacts_version_; }

  // What happened to bodies since clear_body_events(), each body once with every flag that
  // applies (Box2D v3's body move events, widened): made, removed, moved (every body a step
  // integrates, and those set_motion or an impulse changed), woken, fallen asleep. A caller that
  // mirrors the world (the server's frames) touches only these: a world of sleeping bodies lists
  // none. Between two clears the list holds at most 2 slots + 4096 entries; beyond that (bodies
  // made and removed over and over) it is emptied and body_events_complete() turns false until
  // the next clear: treat every body as changed then, as after from_state().
  std::span<const BodyEvent> body_events() const { return events_; }
  bool body_events_complete() const { return events_complete_; }
  void clear_body_events();

  // Broad phase: pairs of bodies whose world bounds (grown by the contact margin) overlap, at
  // least one of them dynamic, sorted, unique.
  // Ray casts (physics/query.h), between steps (not during one); they read the world and may run
  // from several threads at once. The nearest body each ray meets (RayHit::hit() false for none),
  // one ray or a batch spread over the world's threads (the same answers for any thread count);
  // a ray refused names its entry ("rays[3].direction: must not be zero") and nothing is cast.
  Result<RayHit> cast_ray(const RayCast& ray) const;
  Status cast_rays(std::span<const RayCast> rays, std::span<RayHit> hits) const;
  // Every body the ray meets, nearest first (ties by slot), at most max_hits of them: true when
  // some were left out.
  Result<bool> cast_ray_all(const RayCast& ray, std::size_t max_hits,
                            std::vector<RayHit>* hits) const;
  // The bodies the query's shape overlaps or touches (the narrow phase's exact test), in slot
  // order, at most max_bodies of them: true when some were left out. A shape refused names its
  // field ("shape.radius: must be > 0").
  Result<bool> overlap(const OverlapQuery& query, std::size_t max_bodies,
                       std::vector<BodyId>* bodies) const;
  // The first body a shape meets along its sweep (ShapeHit::hit() false for none; equal
  // fractions go to the lower slot): one cast, or a batch spread over the world's threads (the
  // same answers for any thread count). A cast refused names its entry ("casts[2].shape.radius:
  // must be > 0") and nothing is cast. `max_candidates` bounds the bodies the batch's swept bounds
  // may reach (each is then met by up to kShapeCastIterations narrow-phase calls): past it the
  // batch is refused before any is tested.
  Result<ShapeHit> cast_shape(const ShapeCast& cast) const;
  Status cast_shapes(std::span<const ShapeCast> casts, std::span<ShapeHit> hits,
                     std::size_t max_candidates = static_cast<std::size_t>(-1)) const;
  // The point of the body's surface nearest to `point` (m, world), if within max_distance (m,
  // > 0 and <= 1e10; a point inside always is); the narrow phase's exact distance.
  Result<ClosestPoint> closest_point(BodyId body, const Vec3& point, double max_distance) const;

  std::span<const BodyPair> find_pairs();
  // Broad and narrow phase: every touching pair's manifold, in pair order.
  std::span<const Contact> find_contacts();
  // Flags raised by the narrow phase in the last find_contacts() (see CollisionFlags).
  std::uint32_t collision_flags() const { return collision_flags_; }

 private:
  friend struct WorldInternals;  // the engine's own state encoding and tests (physics/src)
  static constexpr std::uint32_t kNoSlot = UINT32_MAX;
  struct Slot;  // a body and its slot's generation (physics/src/world_slot.h)
  // Joints by slot (physics/src/joint_state.h), as bodies are kept.
  std::vector<JointSlot> joints_;
  std::vector<std::uint32_t> free_joint_slots_;
  std::size_t joint_count_ = 0;
  std::vector<std::uint32_t> joints_of_body_;  // per body slot
  // The body pairs whose joints keep them from colliding (low slot << 32 | high slot), sorted,
  // once per joint: the narrow phase skips them.
  std::vector<std::uint64_t> unjoined_pairs_;
  void remove_joints_of(std::uint32_t body_slot);
  void wake_joint(const Joint& joint);  // its sleeping bodies
  // joint_count_, joints_of_body_ and unjoined_pairs_ from joints_ (a restored state).
  void restore_joint_indexes();
  // out[i] = 1 where a joint keeps pairs[i] apart (pairs sorted, as the broad phase gives them).
  void mark_unjoined(std::span<const BodyPair> pairs, std::span<std::uint8_t> out) const;
  // Sleepers joined to moving bodies wake with their islands; returns how many woke.
  std::uint32_t wake_jointed();
  // The sleepers a static body's joints hold wake (it moved).
  void wake_joined_to(std::uint32_t body_slot);
  // The step's joints: rows for those with a moving body, their links into islands.
  void prepare_joint_rows();
  void store_joint_impulses();
  std::uint32_t wake_island(std::uint32_t island);
  // Links the bodies that fall asleep together into their island's set (sleepers_).
  void link_sleeper(std::uint32_t slot, std::uint32_t island);
  // Wakes every sleeping island whose bounds come near `body` (it moved or is going away).
  void wake_around(const Body& body);
  // After the narrow phase: sleepers touched by moving bodies wake with their islands; returns
  // how many woke.
  std::uint32_t wake_touched();
  void update_sleep(double dt);
  void compute_bounds(double dt);
  void run_broad_phase();
  void find_contacts(double dt);
  // Stages of step(), in order (physics/src/step_stages.h lists them with their files).
  void number_solver_bodies();  // StepScratch's solver indices, for load_solver_bodies
  void load_solver_bodies();
  void prepare_contact_rows();
  void choose_island_solvers(double dt);
  void group_for_sweeps();
  void solve_islands(double dt);
  void correct_positions(double dt);
  void sweep_fast_bodies(double dt);
  void finish_step(double dt);

  WorldSettings settings_;
  std::vector<Slot> bodies_;
  // body_events(): per slot, the entry of its current body in events_ (kNoSlot: none).
  std::vector<BodyEvent> events_;
  std::vector<std::uint32_t> event_of_slot_;
  bool events_complete_ = true;
  void note_event(std::uint32_t slot, std::uint8_t flag);
  std::vector<std::uint32_t> free_slots_;
  // Sleeping islands as sets, so that waking one visits its bodies, not every slot: the island
  // with id i (its bodies' sleep_island) starts at sleeper_head_[i] and goes on through
  // sleeper_next_ (both by slot; UINT32_MAX ends a list).
  std::vector<std::uint32_t> sleeper_head_, sleeper_next_;
  // The moving bodies' slots (dynamic and awake), so that a step visits them and not every slot:
  // bodies join when they are made or wake, and leave when they fall asleep or are removed. The
  // step wants them in slot order (it numbers its solver bodies so, and islands by their lowest
  // body); joining may break the order, which the next step restores. Bodies removed or made to
  // rest leave it lazily (awake_stale_): awake_slots() drops them.
  std::vector<std::uint32_t> awake_;
  bool awake_sorted_ = true, awake_stale_ = false;
  // The kinematic bodies' slots, in no order: the step moves those with a velocity (carries()),
  // which are few, and treats the rest as statics. A world without pays one test of emptiness.
  std::vector<std::uint32_t> kinematic_;
  // How many live bodies are terrain (heightfields): their pairs may give several manifolds
  // (find_contacts); a world without pays one test of zero.
  std::size_t many_manifold_bodies_ = 0;  // terrain and compounds (makes_many_manifolds)
  // The broad phase's moving bodies: awake_ and the kinematic bodies with a velocity, ascending
  // (awake_ itself where there are none).
  std::vector<std::uint32_t> moving_scratch_;
  std::span<const std::uint32_t> broad_phase_moving();
  // Moves the kinematic bodies with a velocity by dt (after the solve).
  void move_kinematic(double dt);
  std::size_t sleeping_count_ = 0;  // bodies in sleeper_head_'s sets
  // Bodies that do not move (statics, sleepers) keep their bounds, and the broad phase their
  // cells, until one of them changes: every change to them (made, removed, moved, asleep, woken)
  // bumps resting_version_; bounds_ were computed at bounds_version_ with bounds_margin_.
  std::uint64_t resting_version_ = 1, bounds_version_ = 0;
  double bounds_margin_ = -1;
  // The slots of those changes since version resting_logged_from_ (the broad phase's last), while
  // they are few: the bounds and the grid's cells are then redone for these slots alone. Versions
  // only grow, so any consumer that saw resting_logged_from_ or later finds every change since in
  // the log. Past its bound (or before the first broad phase) the log is dropped and every
  // resting body is redone.
  // resting_contacts(): per manifold, the island (its sleep_island) it belongs to. Waking an
  // island only marks the store (resting_woken_); the manifolds go in drop_woken_contacts(),
  // once per step or call, however many islands woke.
  std::vector<Contact> resting_contacts_;
  std::vector<double> resting_forces_;
  std::vector<std::uint32_t> resting_island_;
  bool resting_woken_ = false;
  std::uint64_t resting_contacts_version_ = 0;
  void keep_resting_contacts(std::uint32_t island, std::uint32_t island_index, double dt);
  void drop_woken_contacts();
  std::vector<std::uint32_t> resting_log_;
  std::uint64_t resting_logged_from_ = 0;
  bool resting_log_dropped_ = true;
  void resting_changed(std::uint32_t slot);
  void resting_all_changed();
  // Whether the hash grid's resting cells and recent_sleepers_ (bodies fallen asleep since the grid
  // last listed them) hold every sleeper, so that wake_around asks them instead of every slot.
  bool sleepers_indexed_ = false;
  std::vector<std::uint32_t> recent_sleepers_, near_scratch_;
  void join_awake(std::uint32_t slot);
  void leave_awake(std::uint32_t slot);
  // The step's view of awake_: only moving bodies, each once, in slot order.
  std::span<const std::uint32_t> awake_slots();
  std::size_t live_count_ = 0;
  std::vector<Aabb> bounds_;
  std::vector<std::uint8_t> movable_;
  std::vector<BodyPair> pairs_;
  std::vector<Contact> contacts_;
  std::uint32_t collision_flags_ = 0;
  std::vector<double> speculative_;  // m: the gap within which each body gets contacts
  std::vector<double> motion_;       // m: how far each body can move in the step
  std::vector<std::uint8_t> fast_;   // bodies swept by continuous collision this step
  std::uint32_t fast_count_ = 0;
  std::vector<double> impulses_;
  std::unique_ptr<StepScratch> scratch_;
  // Queries' tree of the bodies' bounds (physics/src/query_index.h), rebuilt when the version
  // it was built for is not query_version_ (every step and change of bodies moves it on).
  std::unique_ptr<QueryIndex> query_index_;
  std::uint64_t query_version_ = 0;
  // Whether any body ever had a collision filter other than the default: until one does, pairs
  // are not asked (a world without filters pays nothing for them).
  bool filters_used_ = false;
  const QueryIndex& query_index() const;
  StepStats stats_;
  double time_ = 0;
};

}  // namespace tumble
