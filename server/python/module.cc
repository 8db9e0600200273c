// tumble._engine: the engine in the Python process (client/python/tumble/local.py wraps it as
// tumble.World). Requests travel as the tumble.v1 messages' bytes, as they do to a server; the
// states of many bodies travel as numpy arrays, with no Python loop per body. The GIL is let go
// while the world steps.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <unordered_set>

#include "local_world.h"

namespace py = pybind11;
using tumble::python::LocalLimits;
using tumble::python::LocalWorld;

namespace {

// Raised for every refusal; tumble/local.py turns it into tumble.Error with the gRPC code of the
// same name, as the remote client raises it.
struct Refused : std::exception {
  std::string code, message;
  Refused(const tumble::Status& status) : message(status.message()) {
    switch (status.code()) {
      case tumble::StatusCode::kNotFound:
        code = "NOT_FOUND";
        break;
      case tumble::StatusCode::kResourceExhausted:
        code = "RESOURCE_EXHAUSTED";
        break;
      case tumble::StatusCode::kInvalidArgument:
        code = "INVALID_ARGUMENT";
        break;
      default:
        code = "INTERNAL";
        break;
    }
  }
  const char* what() const noexcept override { return message.c_str(); }
};

void check(const tumble::Status& status) {
  if (!status) throw Refused(status);
}

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Ids = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>;

// An (n, width) array, or a refusal naming `name`.
const double* rows(const std::optional<Doubles>& array, py::ssize_t n, py::ssize_t width,
                   const char* name) {
  if (!array) return nullptr;
  if (array->ndim() != 2 || array->shape(0) != n || array->shape(1) != width)
    check(tumble::Status::error(std::string(name) + ": expected shape (" + std::to_string(n) +
                                ", " + std::to_string(width) + ")"));
  return array->data();
}

// The bodies `ids` name (each once), or every body in slot order when `ids` is None.
std::vector<tumble::BodyId> bodies_of(LocalWorld& local, const std::optional<Ids>& ids,
                                      std::vector<std::uint64_t>* wire) {
  const auto& hosted = local.hosted();
  std::vector<tumble::BodyId> found;
  if (!ids) {
    for (std::uint32_t slot = 0; slot < hosted.world.slot_count(); ++slot)
      if (const tumble::BodyId id = hosted.world.id_at(slot); id.is_valid()) {
        found.push_back(id);
        wire->push_back(hosted.ids.wire(id));
      }
    return found;
  }
  if (ids->ndim() != 1) check(tumble::Status::error("ids: expected a 1-D array of body ids"));
  std::unordered_set<std::uint64_t> seen;
  for (py::ssize_t i = 0; i < ids->shape(0); ++i) {
    const std::uint64_t id = ids->at(i);
    const std::string entry = "ids[" + std::to_string(i) + "]";
    const tumble::BodyId body = hosted.ids.find(id);
    if (!hosted.world.contains(body))
      check(tumble::Status::not_found(entry + ": no body " + std::to_string(id)));
    if (!seen.insert(id).second) check(tumble::Status::error(entry + ": listed twice"));
    found.push_back(body);
    wire->push_back(id);
  }
  return found;
}

template <class T>
py::array_t<T> array_of(const std::vector<T>& values, std::vector<py::ssize_t> shape) {
  py::array_t<T> out(shape);
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

py::dict states(LocalWorld& local, const std::optional<Ids>& ids) {
  std::lock_guard turn(local.mutex());
  std::vector<std::uint64_t> wire;
  const std::vector<tumble::BodyId> bodies = bodies_of(local, ids, &wire);
  const auto n = static_cast<py::ssize_t>(bodies.size());
  Doubles positions({n, py::ssize_t{3}}), orientations({n, py::ssize_t{4}}),
      linear({n, py::ssize_t{3}}), angular({n, py::ssize_t{3}});
  py::array_t<bool> asleep(n);
  double *p = positions.mutable_data(), *q = orientations.mutable_data(),
         *v = linear.mutable_data(), *w = angular.mutable_data();
  bool* s = asleep.mutable_data();
  for (py::ssize_t i = 0; i < n; ++i) {
    const tumble::BodyView body = local.hosted().world.body(bodies[i]);
    const tumble::Vec3 x = body.position(), lv = body.linear_velocity(),
                       av = body.angular_velocity();
    const tumble::Quat o = body.orientation();
    for (int k = 0; k < 3; ++k) {
      p[3 * i + k] = x[k];
      v[3 * i + k] = lv[k];
      w[3 * i + k] = av[k];
    }
    q[4 * i] = o.w(), q[4 * i + 1] = o.x(), q[4 * i + 2] = o.y(), q[4 * i + 3] = o.z();
    s[i] = body.asleep();
  }
  py::dict out;
  out["ids"] = array_of(wire, {n});
  out["positions"] = positions;
  out["orientations"] = orientations;
  out["linear_velocities"] = linear;
  out["angular_velocities"] = angular;
  out["asleep"] = asleep;
  return out;
}

// All or nothing: every row is checked (as SetBodyState checks one) before any is applied.
void set_states(LocalWorld& local, const Ids& ids, const std::optional<Doubles>& positions,
                const std::optional<Doubles>& orientations, const std::optional<Doubles>& linear,
                const std::optional<Doubles>& angular) {
  std::lock_guard turn(local.mutex());
  std::vector<std::uint64_t> wire;
  const std::vector<tumble::BodyId> bodies = bodies_of(local, ids, &wire);
  const auto n = static_cast<py::ssize_t>(bodies.size());
  const double* p = rows(positions, n, 3, "positions");
  const double* q = rows(orientations, n, 4, "orientations");
  const double* v = rows(linear, n, 3, "linear_velocities");
  const double* w = rows(angular, n, 3, "angular_velocities");
  std::vector<tumble::BodyMotion> motions(bodies.size());
  for (py::ssize_t i = 0; i < n; ++i) {
    tumble::BodyMotion& m = motions[i];
    if (p) m.position = tumble::Vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    if (q) m.orientation = tumble::Quat(q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]);
    if (v) m.linear_velocity = tumble::Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    if (w) m.angular_velocity = tumble::Vec3(w[3 * i], w[3 * i + 1], w[3 * i + 2]);
    check(local.hosted().world.check_motion(bodies[i], m).within("[" + std::to_string(i) + "]."));
  }
  for (std::size_t i = 0; i < bodies.size(); ++i)
    local.hosted().world.set_motion(bodies[i], motions[i]);
}

void apply_impulses(LocalWorld& local, const Ids& ids, const Doubles& impulses,
                    const std::optional<Doubles>& points) {
  std::lock_guard turn(local.mutex());
  if (ids.ndim() != 1) check(tumble::Status::error("ids: expected a 1-D array of body ids"));
  const py::ssize_t n = ids.shape(0);
  const double* j = rows(std::optional<Doubles>(impulses), n, 3, "impulses");
  const double* r = rows(points, n, 3, "points");
  const auto& hosted = local.hosted();
  std::vector<tumble::ImpulseAt> batch;
  for (py::ssize_t i = 0; i < n; ++i) {
    const tumble::BodyId body = hosted.ids.find(ids.at(i));
    if (!hosted.world.contains(body))
      check(tumble::Status::not_found("ids[" + std::to_string(i) + "]: no body " +
                                      std::to_string(ids.at(i))));
    batch.push_back(
        {body, tumble::Vec3(j[3 * i], j[3 * i + 1], j[3 * i + 2]),
         r ? std::optional(tumble::Vec3(r[3 * i], r[3 * i + 1], r[3 * i + 2])) : std::nullopt});
  }
  check(local.hosted().world.apply_impulses(batch).within("impulses"));
}

py::dict contacts(LocalWorld& local) {
  std::lock_guard turn(local.mutex());
  const auto frame = local.frame_data();
  // The step's contacts, then the sleepers' (FrameData::contact_tables), as one table.
  tumble::server::ContactTable all;
  for (const tumble::server::ContactTable* table : frame->contact_tables()) {
    all.a.insert(all.a.end(), table->a.begin(), table->a.end());
    all.b.insert(all.b.end(), table->b.begin(), table->b.end());
    all.points.insert(all.points.end(), table->points.begin(), table->points.end());
    all.normals.insert(all.normals.end(), table->normals.begin(), table->normals.end());
    all.depths.insert(all.depths.end(), table->depths.begin(), table->depths.end());
    all.impulses.insert(all.impulses.end(), table->impulses.begin(), table->impulses.end());
  }
  const auto n = static_cast<py::ssize_t>(all.size());
  py::dict out;
  out["body_a"] = array_of(all.a, {n});
  out["body_b"] = array_of(all.b, {n});
  out["points"] = array_of(all.points, {n, 3});
  out["normals"] = array_of(all.normals, {n, 3});
  out["depths"] = array_of(all.depths, {n});
  out["impulses"] = array_of(all.impulses, {n});
  return out;
}

LocalLimits limits_of(std::size_t max_bodies, const std::map<std::string, double>& world) {
  LocalLimits limits;
  limits.max_bodies = max_bodies;
  for (const auto& [name, value] : world) {
    bool known = false;
    for (const tumble::LimitField& field : tumble::limit_fields())
      if (field.name == name) {
        limits.world.*field.value = value;
        known = true;
      }
    if (!known) check(tumble::Status::error("limits." + name + ": no such limit"));
  }
  check(tumble::validate(limits.world).within("limits."));
  if (max_bodies == 0) check(tumble::Status::error("max_bodies: must be > 0"));
  return limits;
}

constexpr int kMaxThreads = 1024;

// Frames of one reader: each steps the world once and describes what is new to this reader.
struct Reader {
  LocalWorld* world;
  tumble::server::FrameOptions options;
  tumble::server::CatalogueDiff diff;
};

}  // namespace

PYBIND11_MODULE(_engine, module) {
  module.doc() = "Tumble's engine in this process (use tumble.World)";
  static py::exception<Refused> refused(module, "Refused");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Refused& e) {
      PyErr_SetObject(refused.ptr(), py::make_tuple(e.code, e.message).ptr());
    }
  });

  py::class_<LocalWorld>(module, "LocalWorld")
      .def(py::init([](int threads, std::size_t max_bodies, std::map<std::string, double> limits) {
             // Each thread of the team is a real thread: bounded as a request's cost is.
             if (threads < 0 || threads > kMaxThreads)
               check(tumble::Status::error("threads: must be in [0, " +
                                           std::to_string(kMaxThreads) + "] (0: every core)"));
             return std::make_unique<LocalWorld>(threads, limits_of(max_bodies, limits));
           }),
           py::arg("threads") = 0, py::arg("max_bodies") = 100000,
           py::arg("limits") = std::map<std::string, double>{})
      .def("call",
           [](LocalWorld& world, const std::string& method, py::bytes request) {
             const std::string in = request;
             tumble::Result<std::string> out = tumble::Status::ok();
             {
               py::gil_scoped_release unlocked;
               std::lock_guard turn(world.mutex());
               out = world.call(method, in);
             }
             check(out.status());
             return py::bytes(out.value());
           })
      .def("step",
           [](LocalWorld& world, std::uint64_t n) {
             tumble::Status stepped = tumble::Status::ok();
             {
               py::gil_scoped_release unlocked;
               std::lock_guard turn(world.mutex());
               stepped = world.step(n);
             }
             check(stepped);
             return world.hosted().world.step_count();
           })
      .def("states", &states, py::arg("ids") = py::none())
      .def("set_states", &set_states, py::arg("ids"), py::arg("positions") = py::none(),
           py::arg("orientations") = py::none(), py::arg("linear_velocities") = py::none(),
           py::arg("angular_velocities") = py::none())
      .def("apply_impulses", &apply_impulses, py::arg("ids"), py::arg("impulses"),
           py::arg("points") = py::none())
      .def("contacts", &contacts)
      .def_property_readonly("running", &LocalWorld::running)
      .def_property_readonly("step_count",
                             [](LocalWorld& world) {
                               std::lock_guard turn(world.mutex());
                               return world.hosted().world.step_count();
                             })
      .def_property_readonly("time", [](LocalWorld& world) {
        std::lock_guard turn(world.mutex());
        return world.hosted().world.time();
      });

  py::class_<Reader>(module, "Reader")
      .def(py::init([](LocalWorld& world, bool velocities, bool contacts, bool stats,
                       std::vector<std::uint64_t> ids, bool joints) {
             auto reader = std::make_unique<Reader>();
             reader->world = &world;
             reader->options.velocities = velocities;
             reader->options.contacts = contacts;
             reader->options.stats = stats;
             reader->options.joints = joints;
             reader->options.ids = std::move(ids);
             std::sort(reader->options.ids.begin(), reader->options.ids.end());
             return reader;
           }),
           py::keep_alive<1, 2>())
      // The frame after one more step (or, with step=False, of the world as it is).
      .def("next", [](Reader& reader, bool step) {
        std::string frame;
        tumble::Status stepped = tumble::Status::ok();
        {
          py::gil_scoped_release unlocked;
          std::lock_guard turn(reader.world->mutex());
          if (step) stepped = reader.world->step(1);
          if (stepped) frame = reader.world->frame(reader.options, reader.diff);
        }
        check(stepped);
        return py::bytes(frame);
      });
}
