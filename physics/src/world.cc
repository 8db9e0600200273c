#include "physics/world.h"

#include <omp.h>

#include <string>

#include "broad_phase.h"

namespace tumble {
namespace {

// Below this many bodies sorting on one axis beats building grids.
constexpr std::size_t kSweepAndPruneBelow = 64;

int thread_count(int requested) {
  return requested > 0 ? requested : omp_get_max_threads();
}

// One grid per thread of the program: the world's own scratch, reused from call to call.
HashGrid& scratch_grid() {
  thread_local HashGrid grid;
  return grid;
}

}  // namespace

World::World(const WorldSettings& settings) : settings_(settings) {}

Result<BodyId> World::create_body(const BodyDef& def) {
  Result<std::vector<BodyId>> ids = create_bodies(std::span<const BodyDef>(&def, 1));
  if (!ids) {
    // A single definition needs no "bodies[0]." prefix.
    const std::string& message = ids.error();
    return Status::error(message.substr(message.find('.') + 1));
  }
  return ids.value()[0];
}

Result<std::vector<BodyId>> World::create_bodies(std::span<const BodyDef> defs) {
  // Build every body first; the world changes only when all of them are valid.
  std::vector<Body> made;
  made.reserve(defs.size());
  for (std::size_t i = 0; i < defs.size(); ++i) {
    Result<Body> body = make_body(defs[i]);
    if (!body) return body.status().within("bodies[" + std::to_string(i) + "].");
    made.push_back(std::move(body).value());
  }
  std::vector<BodyId> ids;
  ids.reserve(made.size());
  for (Body& body : made) {
    std::uint32_t index;
    if (!free_slots_.empty()) {
      index = free_slots_.back();
      free_slots_.pop_back();
    } else {
      index = static_cast<std::uint32_t>(bodies_.size());
      bodies_.emplace_back();
    }
    Slot& slot = bodies_[index];
    slot.body = std::move(body);
    slot.alive = true;
    ids.push_back({index, slot.generation});
    ++live_count_;
  }
  return ids;
}

Status World::remove_body(BodyId id) {
  if (!contains(id)) return Status::error("body: no body with this id");
  Slot& slot = bodies_[id.index];
  slot.alive = false;
  ++slot.generation;
  slot.body = Body();
  free_slots_.push_back(id.index);
  --live_count_;
  return Status::ok();
}

bool World::contains(BodyId id) const {
  return id.index < bodies_.size() && bodies_[id.index].alive &&
         bodies_[id.index].generation == id.generation;
}

const Body* World::body(BodyId id) const {
  return contains(id) ? &bodies_[id.index].body : nullptr;
}

BodyId World::id_at(std::uint32_t index) const {
  if (index >= bodies_.size() || !bodies_[index].alive) return {};
  return {index, bodies_[index].generation};
}

void World::compute_bounds() {
  const std::int64_t n = static_cast<std::int64_t>(bodies_.size());
  bounds_.resize(bodies_.size());
  movable_.resize(bodies_.size());
  const double margin = settings_.collision.margin;
#pragma omp parallel for schedule(static) num_threads(thread_count(settings_.threads)) if (n > 256)
  for (std::int64_t i = 0; i < n; ++i) {
    const Slot& slot = bodies_[i];
    if (!slot.alive) {
      bounds_[i] = Aabb();
      movable_[i] = 0;
      continue;
    }
    bounds_[i] = transform_aabb(slot.body.shape.local_bounds(), slot.body.pose()).expanded(margin);
    movable_[i] = slot.body.is_static() ? 0 : 1;
  }
}

std::span<const BodyPair> World::find_pairs() {
  compute_bounds();
  const BroadPhaseInput input{bounds_, movable_, thread_count(settings_.threads)};
  BroadPhaseMethod method = settings_.broad_phase;
  if (method == BroadPhaseMethod::kAuto)
    method = live_count_ < kSweepAndPruneBelow ? BroadPhaseMethod::kSweepAndPrune
                                               : BroadPhaseMethod::kHashGrid;
  if (method == BroadPhaseMethod::kSweepAndPrune)
    sweep_and_prune(input, &pairs_);
  else
    scratch_grid().find_pairs(input, &pairs_);
  return pairs_;
}

std::span<const Contact> World::find_contacts() {
  find_pairs();
  const std::int64_t n = static_cast<std::int64_t>(pairs_.size());
  // Every pair writes its own slot, then the touching ones are packed in pair order: the same
  // result for any thread count.
  contacts_.resize(pairs_.size());
  std::uint32_t flags = 0;
#pragma omp parallel for schedule(static) num_threads(thread_count(settings_.threads)) \
    reduction(|                                                                        \
              : flags) if (n > 64)
  for (std::int64_t i = 0; i < n; ++i) {
    const Body& a = bodies_[pairs_[i].a].body;
    const Body& b = bodies_[pairs_[i].b].body;
    Contact& contact = contacts_[i];
    contact.a = {pairs_[i].a, bodies_[pairs_[i].a].generation};
    contact.b = {pairs_[i].b, bodies_[pairs_[i].b].generation};
    flags |= collide(a.shape, a.pose(), b.shape, b.pose(), settings_.collision, &contact.manifold);
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < contacts_.size(); ++i)
    if (contacts_[i].manifold.count > 0) contacts_[kept++] = contacts_[i];
  contacts_.resize(kept);
  collision_flags_ = flags;
  return contacts_;
}

}  // namespace tumble
