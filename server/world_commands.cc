#include "world_commands.h"

#include <algorithm>
#include <charconv>
#include <unordered_set>

#include "convert.h"
#include "request_bounds.h"
#include "scenes/standard.h"
#include "tumble/v1/snapshot.pb.h"

namespace tumble::server {
namespace {

std::string entry(const char* list, int i) {
  return std::string(list) + "[" + std::to_string(i) + "]";
}

// The body each entry's id names, refusing the first unknown one ("updates[2].id: no body 9").
template <class Entries>
Status find_entries(const HostedWorld& hosted, const char* list, const Entries& entries,
                    std::vector<BodyId>* ids) {
  ids->reserve(entries.size());
  for (int i = 0; i < entries.size(); ++i) {
    const BodyId id = hosted.ids.find(entries[i].id());
    if (!hosted.world.contains(id))
      return Status::not_found(entry(list, i) + ".id: no body " + std::to_string(entries[i].id()));
    ids->push_back(id);
  }
  return Status::ok();
}

// A query's shape placed in the world (OverlapQuery, ShapeCastQuery): its shape, position,
// orientation (identity when absent) and mask, which the engine checks.
template <class Asked, class Query>
Status place_shape(const Asked& asked, const std::string& at, Query* query) {
  Result<ShapeDef> shape = shape_def_from_proto(asked.shape());
  if (!shape) return shape.status().within(at);
  query->shape = std::move(shape).value();
  query->pose.position = vec_from_proto(asked.position());
  if (asked.has_orientation()) {
    const v1::Quat& q = asked.orientation();
    query->pose.orientation = Quat(q.w(), q.x(), q.y(), q.z());
  }
  if (asked.has_mask()) query->mask = asked.mask();
  return Status::ok();
}

}  // namespace

Status find_bodies(const HostedWorld& hosted, const WireIds& wire_ids, std::vector<BodyId>* ids) {
  for (int i = 0; i < wire_ids.size(); ++i) {
    const BodyId id = hosted.ids.find(wire_ids[i]);
    if (!hosted.world.contains(id))
      return Status::not_found(entry("ids", i) + ": no body " + std::to_string(wire_ids[i]));
    ids->push_back(id);
  }
  return Status::ok();
}

Status refuse_repeats(const WireIds& ids) {
  std::unordered_set<std::uint64_t> seen;
  seen.reserve(static_cast<std::size_t>(ids.size()));
  for (int i = 0; i < ids.size(); ++i)
    if (!seen.insert(ids[i]).second) return Status::error(entry("ids", i) + ": listed twice");
  return Status::ok();
}

Result<std::vector<BodyDef>> body_defs(const v1::SpawnBodiesRequest& request) {
  std::vector<BodyDef> defs;
  defs.reserve(request.bodies_size());
  for (int i = 0; i < request.bodies_size(); ++i) {
    Result<BodyDef> def = body_from_proto(request.bodies(i));
    if (!def) return Status::error(entry("bodies", i) + "." + def.error());
    defs.push_back(std::move(def).value());
  }
  return defs;
}

Status spawn_bodies(HostedWorld& hosted, const std::vector<BodyDef>& defs,
                    const v1::SpawnBodiesRequest& request, std::size_t max_bodies,
                    std::vector<std::uint64_t>* ids) {
  World& world = hosted.world;
  if (world.body_count() + defs.size() > max_bodies)
    return Status::error("bodies: " + std::to_string(defs.size()) + " more would exceed the " +
                             std::to_string(max_bodies) + " bodies allowed",
                         StatusCode::kResourceExhausted);
  Result<std::vector<BodyId>> made = world.create_bodies(defs);
  if (!made) {
    // "bodies[i].shape.…" (the world's limits): the field in the API's terms.
    const std::string& message = made.error();
    const std::size_t close = message.find("].");
    int index = -1;
    if (message.rfind("bodies[", 0) == 0 && close != std::string::npos)
      std::from_chars(message.data() + 7, message.data() + close, index);
    if (index < 0 || index >= request.bodies_size()) return made.status();
    return Status::error(message.substr(0, close + 2) +
                             in_api_terms(message.substr(close + 2), request.bodies(index).shape()),
                         made.status().code());
  }
  hosted.ids.sync(world);
  for (std::size_t i = 0; i < made.value().size(); ++i) {
    hosted.set_colour(made.value()[i], request.bodies(static_cast<int>(i)).color());
    ids->push_back(hosted.ids.wire(made.value()[i]));
  }
  return Status::ok();
}

Status remove_bodies(HostedWorld& hosted, const WireIds& wire_ids) {
  if (Status twice = refuse_repeats(wire_ids); !twice) return twice;
  // Every id is checked before anything is removed: all or nothing.
  std::vector<BodyId> ids;
  if (Status found = find_bodies(hosted, wire_ids, &ids); !found) return found;
  for (BodyId id : ids)
    hosted.world.remove_body(id);
  return Status::ok();
}

Status get_bodies(const HostedWorld& hosted, const v1::GetBodiesRequest& request,
                  v1::GetBodiesResponse* response) {
  // An id asked for twice would be answered twice: the reply could grow past any bound.
  if (Status twice = refuse_repeats(request.ids()); !twice) return twice;
  const World& world = hosted.world;
  std::vector<BodyId> ids;
  if (request.ids_size() == 0) {
    for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot)
      if (world.id_at(slot).is_valid()) ids.push_back(world.id_at(slot));
  } else if (Status found = find_bodies(hosted, request.ids(), &ids); !found) {
    return found;
  }
  response->set_step(world.step_count());
  for (BodyId id : ids) {
    const BodyView body = world.body(id);
    const std::uint32_t colour = id.index < hosted.colours.size() ? hosted.colours[id.index] : 0;
    v1::BodyDescription* description = response->add_descriptions();
    describe(hosted.ids.wire(id), look_of(body, colour), description);
    describe_forces(body, description);
    v1::BodyState* state = response->add_states();
    state->set_id(hosted.ids.wire(id));
    vec_to_proto(body.position(), state->mutable_position());
    const Quat q = body.orientation();
    state->mutable_orientation()->set_w(q.w());
    state->mutable_orientation()->set_x(q.x());
    state->mutable_orientation()->set_y(q.y());
    state->mutable_orientation()->set_z(q.z());
    vec_to_proto(body.linear_velocity(), state->mutable_linear_velocity());
    vec_to_proto(body.angular_velocity(), state->mutable_angular_velocity());
    state->set_asleep(body.asleep());
  }
  return Status::ok();
}

Status query(const HostedWorld& hosted, const v1::QueryRequest& request,
             v1::QueryResponse* response) {
  const std::size_t numbers = static_cast<std::size_t>(request.ray_origins_size());
  if (numbers % 3 != 0)
    return Status::error("ray_origins: must be x y z triples (" + std::to_string(numbers) +
                         " numbers)");
  const std::size_t n = numbers / 3;
  if (static_cast<std::size_t>(request.ray_directions_size()) != numbers)
    return Status::error("ray_directions: must hold as many numbers as ray_origins (" +
                         std::to_string(numbers) + ")");
  const std::size_t distances = static_cast<std::size_t>(request.ray_max_distances_size());
  if (distances > 1 && distances != n)
    return Status::error("ray_max_distances: one for every ray, or one per ray (" +
                         std::to_string(n) + ")");
  if (n > kMaxQueryRays)
    return Status::error("ray_origins: " + std::to_string(n) +
                             " rays, above the 262144 a query may cast",
                         StatusCode::kResourceExhausted);
  const std::size_t per_ray = request.hits_per_ray();
  if (per_ray > kMaxHitsPerRay)
    return Status::error("hits_per_ray: must be in [0, 64]");
  if (n * std::max<std::size_t>(per_ray, 1) > kMaxQueryHits)
    return Status::error("hits_per_ray: " + std::to_string(n) + " rays x " +
                             std::to_string(per_ray) +
                             " hits is above the 262144 hits a query may answer",
                         StatusCode::kResourceExhausted);
  if (static_cast<std::size_t>(request.overlaps_size()) > kMaxQueryOverlaps)
    return Status::error("overlaps: " + std::to_string(request.overlaps_size()) +
                             " queries, above the 256 a request may hold",
                         StatusCode::kResourceExhausted);
  std::vector<OverlapQuery> overlaps(request.overlaps_size());
  for (int i = 0; i < request.overlaps_size(); ++i) {
    const std::string at = "overlaps[" + std::to_string(i) + "].";
    if (Status s = place_shape(request.overlaps(i), at, &overlaps[i]); !s) return s;
  }
  if (static_cast<std::size_t>(request.closest_points_size()) > kMaxQueryClosest)
    return Status::error("closest_points: " + std::to_string(request.closest_points_size()) +
                             " queries, above the 65536 a request may hold",
                         StatusCode::kResourceExhausted);
  std::vector<BodyId> closest_bodies;
  if (Status found = find_entries(hosted, "closest_points", request.closest_points(),
                                  &closest_bodies);
      !found)
    return found;
  if (static_cast<std::size_t>(request.shape_casts_size()) > kMaxQueryShapeCasts)
    return Status::error("shape_casts: " + std::to_string(request.shape_casts_size()) +
                             " casts, above the 1024 a request may hold",
                         StatusCode::kResourceExhausted);
  std::vector<ShapeCast> casts(request.shape_casts_size());
  for (int i = 0; i < request.shape_casts_size(); ++i) {
    const std::string at = "shape_casts[" + std::to_string(i) + "].";
    if (Status s = place_shape(request.shape_casts(i), at, &casts[i]); !s) return s;
    casts[i].translation = vec_from_proto(request.shape_casts(i).translation());
  }
  std::vector<RayCast> rays(n);
  for (std::size_t i = 0; i < n; ++i) {
    RayCast& ray = rays[i];
    ray.origin = Vec3(request.ray_origins(3 * i), request.ray_origins(3 * i + 1),
                      request.ray_origins(3 * i + 2));
    ray.direction = Vec3(request.ray_directions(3 * i), request.ray_directions(3 * i + 1),
                         request.ray_directions(3 * i + 2));
    if (distances > 0) ray.max_distance = request.ray_max_distances(distances == 1 ? 0 : i);
    if (request.has_ray_mask()) ray.mask = request.ray_mask();
    if (Status s = validate(ray); !s) return s.within("rays[" + std::to_string(i) + "].");
  }
  const World& world = hosted.world;
  response->set_step(world.step_count());
  if (!casts.empty()) {
    std::vector<ShapeHit> cast_hits(casts.size());
    if (Status s = world.cast_shapes(casts, cast_hits, kMaxCastCandidates); !s) {
      // The engine names its entries casts[i]; the request's field is shape_casts.
      if (s.message().rfind("casts", 0) == 0)
        return Status::error("shape_" + s.message(), s.code());
      return s;
    }
    for (const ShapeHit& hit : cast_hits) {
      response->add_cast_hits(hit.hit());
      response->add_cast_ids(hit.hit() ? hosted.ids.wire(hit.body) : 0);
      response->add_cast_fractions(hit.fraction);
      for (int k = 0; k < 3; ++k)
        response->add_cast_points(hit.point[k]);
      for (int k = 0; k < 3; ++k)
        response->add_cast_normals(hit.normal[k]);
      response->add_cast_converged(hit.converged);
    }
  }
  // Overlaps first (each refused before any answer is kept), the rays after: a refused overlap
  // leaves no half-written answer.
  std::vector<BodyId> bodies;
  std::size_t room = kMaxQueryHits;
  for (std::size_t i = 0; i < overlaps.size(); ++i) {
    Result<bool> left_out = world.overlap(overlaps[i], room, &bodies);
    if (!left_out) return left_out.status().within("overlaps[" + std::to_string(i) + "].");
    response->set_overlaps_left_out(response->overlaps_left_out() || left_out.value());
    response->add_overlap_counts(static_cast<std::uint32_t>(bodies.size()));
    for (BodyId id : bodies)
      response->add_overlap_ids(hosted.ids.wire(id));
    room -= bodies.size();
  }
  for (int i = 0; i < request.closest_points_size(); ++i) {
    const v1::ClosestPointQuery& asked = request.closest_points(i);
    Result<ClosestPoint> found =
        world.closest_point(closest_bodies[i], vec_from_proto(asked.point()),
                            asked.has_max_distance() ? asked.max_distance() : 1000.0);
    if (!found) return found.status().within("closest_points[" + std::to_string(i) + "].");
    const ClosestPoint& c = found.value();
    response->add_closest_found(c.found);
    response->add_closest_distances(c.distance);
    for (int k = 0; k < 3; ++k)
      response->add_closest_surface_points(c.point[k]);
    for (int k = 0; k < 3; ++k)
      response->add_closest_normals(c.normal[k]);
  }
  auto add_hit = [&](const RayHit& hit) {
    response->add_hit_ids(hosted.ids.wire(hit.body));
    response->add_hit_distances(hit.distance);
    response->add_hit_fractions(hit.fraction);
    for (int k = 0; k < 3; ++k)
      response->add_hit_points(hit.point[k]);
    for (int k = 0; k < 3; ++k)
      response->add_hit_normals(hit.normal[k]);
  };
  if (per_ray == 0) {
    std::vector<RayHit> hits(n);
    if (Status s = world.cast_rays(rays, hits); !s) return s;
    for (const RayHit& hit : hits) {
      response->add_hit_counts(hit.hit() ? 1 : 0);
      if (hit.hit()) add_hit(hit);
    }
    return Status::ok();
  }
  std::vector<RayHit> hits;
  for (const RayCast& ray : rays) {
    Result<bool> left_out = world.cast_ray_all(ray, per_ray, &hits);
    if (!left_out) return left_out.status();
    response->set_hits_left_out(response->hits_left_out() || left_out.value());
    response->add_hit_counts(static_cast<std::uint32_t>(hits.size()));
    for (const RayHit& hit : hits)
      add_hit(hit);
  }
  return Status::ok();
}

Status set_body_states(HostedWorld& hosted, const v1::SetBodyStateRequest& request) {
  std::vector<BodyId> ids;
  if (Status found = find_entries(hosted, "updates", request.updates(), &ids); !found) return found;
  auto motion = [&](int i) {
    return motion_from_proto(request.updates(i), hosted.world.body(ids[i]).filter());
  };
  for (int i = 0; i < request.updates_size(); ++i)
    if (Status s = hosted.world.check_motion(ids[i], motion(i)); !s)
      return s.within(entry("updates", i) + ".");
  for (int i = 0; i < request.updates_size(); ++i)
    hosted.world.set_motion(ids[i], motion(i));
  return Status::ok();
}

Status apply_impulses(HostedWorld& hosted, const v1::ApplyImpulseRequest& request) {
  std::vector<BodyId> ids;
  if (Status found = find_entries(hosted, "impulses", request.impulses(), &ids); !found)
    return found;
  std::vector<ImpulseAt> impulses;
  impulses.reserve(ids.size());
  for (int i = 0; i < request.impulses_size(); ++i) {
    const v1::Impulse& impulse = request.impulses(i);
    impulses.push_back({ids[i], vec_from_proto(impulse.impulse()),
                        impulse.has_point() ? std::optional<Vec3>(vec_from_proto(impulse.point()))
                                            : std::nullopt});
  }
  // Several impulses on one body add up, and are checked as their sum: all or nothing.
  if (Status s = hosted.world.apply_impulses(impulses); !s) return s.within("impulses");
  return Status::ok();
}

Result<SceneDef> scene_of(const v1::LoadSceneRequest& request, std::size_t max_bodies) {
  Result<SceneDef> scene = Status::error("source: required (scene_json or builtin)");
  if (request.has_scene_json())
    scene = parse_scene(request.scene_json(), max_bodies);
  else if (request.has_builtin())
    scene = standard_scene(request.builtin(), max_bodies);
  if (!scene) {
    const char* field = request.has_scene_json() ? "scene_json: "
                        : request.has_builtin()  ? "builtin: "
                                                 : "";
    return scene.status().within(field);
  }
  return scene;
}

Result<World> world_of_scene(SceneDef scene, const WorldLimits& limits, std::size_t max_bodies) {
  scene.world.limits = limits;
  if (Status t = check_time_step(scene.dt, limits); !t)
    return Status::error("scene: " + t.message());
  if (scene.bodies.size() > max_bodies)
    return Status::error("scene: " + std::to_string(scene.bodies.size()) +
                             " bodies, more than the " + std::to_string(max_bodies) + " allowed",
                         StatusCode::kResourceExhausted);
  Result<World> made = make_world(scene);
  if (!made) return Status::error("scene: " + made.error());
  return made;
}

Status replace_world(HostedWorld& hosted, World world, double dt, std::vector<std::uint64_t>* ids) {
  WorldSettings settings = world.settings();
  settings.threads = hosted.world.settings().threads;  // the host's choice, not the scene's
  if (Status s = world.set_settings(settings); !s) return s;
  hosted.replace(std::move(world), dt, {});
  for (std::uint32_t slot = 0; slot < hosted.world.slot_count(); ++slot)
    if (const BodyId id = hosted.world.id_at(slot); id.is_valid())
      ids->push_back(hosted.ids.wire(id));
  return Status::ok();
}

SavedWorld save_world(const HostedWorld& hosted) {
  return {hosted.world.settings(), hosted.world.save_state(), hosted.dt,
          hosted.colours,          hosted.ids.by_slot(),      hosted.ids.next(),
          hosted.server_instance,  hosted.world.step_count(), hosted.joint_ids.by_slot(),
          hosted.joint_ids.next()};
}

Result<RestoredWorld> decode_restore(std::string_view bytes, const WorldLimits& limits,
                                     std::size_t max_bodies) {
  // The snapshot's slots (live or free) are counted, and what decoding it would take is
  // bounded, before it is decoded: every slot costs memory and every step's time.
  const Result<WireScan> scan = scan_wire(bytes, *v1::snapshot::WorldSnapshot::descriptor(),
                                          parsed_bound(bytes.size()), max_bodies);
  if (!scan) {
    if (scan.status().code() == StatusCode::kResourceExhausted)
      return Status::error("state: " + scan.error() + " (slots, live or free, count against the " +
                               std::to_string(max_bodies) + " bodies allowed)",
                           StatusCode::kResourceExhausted);
    return Status::error("state: not a snapshot (" + scan.error() + ")");
  }
  Result<SavedWorld> decoded = decode_snapshot(bytes);
  if (!decoded) return Status::error("state." + decoded.error());
  SavedWorld& saved = decoded.value();
  saved.settings.limits = limits;
  if (Status t = check_time_step(saved.dt, limits); !t)
    return Status::error("state." + t.message());
  Result<World> world = World::from_state(saved.settings, saved.state);
  if (!world) return Status::error("state.engine_state." + world.error());
  for (std::uint32_t slot = 0; slot < saved.ids.size(); ++slot)
    if (saved.ids[slot] != 0 && !world.value().id_at(slot).is_valid())
      return Status::error("state.ids[" + std::to_string(slot) + "]: a free slot has no id");
  return RestoredWorld{std::move(world).value(), std::move(saved)};
}

Status restore_world(HostedWorld& hosted, RestoredWorld restored,
                     google::protobuf::Map<std::uint64_t, std::uint64_t>* new_ids) {
  World& world = restored.world;
  SavedWorld& saved = restored.saved;
  WorldSettings settings = world.settings();
  settings.threads = hosted.world.settings().threads;  // the host's choice
  if (Status t = world.set_settings(settings); !t) return t;
  if (saved.server_instance == hosted.server_instance) {
    // Ids this host gave to these very bodies: they keep them.
    hosted.restore(std::move(world), saved.dt, std::move(saved.colours), saved.ids, saved.next_id,
                   saved.joint_ids, saved.next_joint_id);
    return Status::ok();
  }
  // Another host's ids could name bodies of ours: every body gets a new one.
  hosted.replace(std::move(world), saved.dt, std::move(saved.colours));
  for (std::uint32_t slot = 0; slot < saved.ids.size(); ++slot)
    if (const BodyId id = hosted.world.id_at(slot); id.is_valid() && saved.ids[slot] != 0)
      (*new_ids)[saved.ids[slot]] = hosted.ids.wire(id);
  return Status::ok();
}

}  // namespace tumble::server
