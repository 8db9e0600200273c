// Stage "rows": every manifold's rows (one per contact point) built in parallel, each pair
// keeping the solver colour it was given when it started touching.
#include <algorithm>

#include "auto_solver.h"
#include "colouring.h"
#include "contact_packs.h"
#include "contact_pairs.h"
#include "contact_solver.h"
#include "islands.h"
#include "parallel.h"
#include "physics/world.h"
#include "step_scratch.h"
#include "step_stages.h"
#include "tall_stacks.h"
#include "world_slot.h"

namespace tumble {

void World::prepare_contact_rows() {
  StepScratch& s = *scratch_;
  const int threads = team_size(settings_.threads);
  // Every manifold's rows have a place known in advance, so they are built in parallel.
  const std::size_t manifolds = contacts_.size();
  s.row_begin.resize(manifolds + 1);
  s.row_begin[0] = 0;
  s.links.resize(manifolds);
  s.touching.resize(manifolds);
  s.kept_colours.resize(manifolds);
  s.colours.resize(manifolds);
  s.manifold_depth.resize(manifolds);
  const std::int64_t count = static_cast<std::int64_t>(manifolds);
  // What each manifold says of itself, read over the team (the contacts are large and each is
  // read once); then the places of the rows, a count on one thread over a word per manifold.
  for_indices(threads, worth_a_team(count, 7), count, [&](std::int64_t m) {
    const Contact& contact = contacts_[m];
    s.row_begin[m + 1] = static_cast<std::uint32_t>(contact.manifold.count);
    s.links[m] = {s.solver_of_slot[contact.a.index], s.solver_of_slot[contact.b.index]};
    s.touching[m] = contact.manifold.depth > -settings_.solver.slop;
    s.manifold_depth[m] = contact.manifold.depth;
    const std::uint32_t previous = s.previous_pair[m];
    s.kept_colours[m] = previous == kNoRecord ? kNoColour : s.pairs[previous].colour;
  });
  double deepest = 0;
  for (std::size_t m = 0; m < manifolds; ++m) {
    s.row_begin[m + 1] += s.row_begin[m];
    stats_.reused_manifolds += s.reused[m];
    deepest = std::max(deepest, s.manifold_depth[m]);
  }
  // A pair keeps the colour it was given when it started touching (colouring.h); its record
  // carries it to the next step (below, with the rows).
  keep_manifold_colours(s.links, s.dynamic, s.kept_colours, &s.colouring_scratch, s.colours);
  resize_for_overwrite(s.rows, s.row_begin[manifolds]);
  resize_for_overwrite(s.cold_rows, s.rows.size());
  resize_for_overwrite(s.blocks, manifolds);
  if (s.row_ids.size() < s.rows.size()) {
    const std::size_t from = s.row_ids.size();
    s.row_ids.resize(s.rows.size());
    for (std::size_t r = from; r < s.row_ids.size(); ++r)
      s.row_ids[r] = static_cast<std::uint32_t>(r);
  }
  for_indices(threads, worth_a_team(count, 190), count, [&](std::int64_t m) {
    s.next_pairs[m].colour = s.colours[m];
    const Contact& contact = contacts_[m];
    const std::uint32_t previous = s.previous_pair[m];
    prepare_rows(contact.manifold, s.links[m].a, bodies_[contact.a.index].body, s.links[m].b,
                 bodies_[contact.b.index].body,
                 previous == kNoRecord ? nullptr : &s.pairs[previous],
                 static_cast<std::uint32_t>(m), &s.rows[s.row_begin[m]],
                 &s.cold_rows[s.row_begin[m]], &s.blocks[m]);
  });
  stats_.max_penetration = deepest;
}

}  // namespace tumble
