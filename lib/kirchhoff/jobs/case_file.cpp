#include "kirchhoff/jobs/case_file.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <toml.hpp>

#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/contact/plectoneme.hpp"
#include "kirchhoff/contact/self_contact.hpp"
#include "kirchhoff/jobs/detail/case_reader.hpp"
#include "kirchhoff/jobs/detail/toml_nesting.hpp"
#include "kirchhoff/model/detail/expression.hpp"

namespace kirchhoff {

using namespace case_reading;

namespace {

// A frame given as a matrix or as directors is a rotation when its columns are orthonormal and
// right-handed to this: 10 significant digits ("0.8660254038" for sqrt(3)/2) are 1e-10 off, and
// a frame further off than 1e-9 is a typing error, not rounding (expressions give exact values).
constexpr double kFrameTolerance = 1e-9;

// One constant direction of a frame (a director or a matrix column): no parameters, since the
// frame is checked to be a rotation once, here.
Vec3 frame_vector(const Reader& reader, const std::array<Expression, 3>& e, const Value& where, const std::string& key,
                  const Parameters& parameters) {
  for (const auto& component : e)
    if (!component.used_parameters().empty())
      reader.fail(where, key, "a frame given by a matrix or directors is fixed: a frame that moves with '" +
                                  component.used_parameters().front() + "' is given as axis and angle");
  return Vec3(e[0](parameters), e[1](parameters), e[2](parameters));
}

// The frame {matrix = [[..], [..], [..]]} (rows; its columns are d1, d2, d3) or two or three of
// {d1, d2, d3} (the third d3 = d1 x d2, d1 = d2 x d3, d2 = d3 x d1), checked to be a rotation.
Mat3 frame_from_table(const Reader& reader, const Value& v, const std::string& key, const Parameters& parameters) {
  Mat3 R = Mat3::Zero();
  if (const Value* m = Reader::find(v, "matrix")) {
    if (!m->is_array() || m->as_array().size() != 3)
      reader.fail(*m, key + ".matrix", "must be 3 rows of 3 numbers: [[R11, R12, R13], [R21, ...], [R31, ...]]");
    for (int i = 0; i < 3; ++i) {
      const Value& row = m->as_array()[static_cast<std::size_t>(i)];
      if (!row.is_array() || row.as_array().size() != 3) reader.fail(row, key + ".matrix", "each row has 3 numbers");
      R.row(i) = frame_vector(reader, reader.vector(row, key + ".matrix"), row, key + ".matrix", parameters);
    }
  } else {
    std::array<const Value*, 3> d{Reader::find(v, "d1"), Reader::find(v, "d2"), Reader::find(v, "d3")};
    const int given = (d[0] != nullptr) + (d[1] != nullptr) + (d[2] != nullptr);
    if (given < 2) reader.fail(v, key, "give two or three of d1, d2, d3 (one leaves the frame free to turn about it)");
    for (int i = 0; i < 3; ++i) {
      const std::string name = key + ".d" + std::to_string(i + 1);
      if (d[i]) R.col(i) = frame_vector(reader, reader.vector(*d[i], name), *d[i], name, parameters);
    }
    for (int i = 0; i < 3; ++i)  // the missing one completes a right-handed frame
      if (!d[i]) R.col(i) = R.col((i + 1) % 3).cross(R.col((i + 2) % 3));
  }
  const double off = (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff();
  std::ostringstream why;
  why.precision(3);
  if (!(off <= kFrameTolerance)) {
    why << "the directors are not orthonormal: |R^T R - I| = " << off << " > " << kFrameTolerance
        << " (give 10 digits or expressions such as \"sqrt(3)/2\")";
    reader.fail(v, key, why.str());
  }
  if (R.determinant() < 0)
    reader.fail(v, key, "the directors are left-handed (det = -1, a reflection): d3 must be d1 x d2");
  return R;
}

// Whether an orientation table gives the frame itself (a matrix or directors).
bool gives_frame(const Value& v) {
  return Reader::find(v, "matrix") || Reader::find(v, "d1") || Reader::find(v, "d2") || Reader::find(v, "d3");
}

// The rotation that takes the equations' reference frame to R, as the axis and angle the end
// conditions impose; a planar rod's turns about e_z only (its d2 stays e_z).
OrientationTarget rotation_to(const Reader& reader, const Value& v, const std::string& key, const Mat3& R,
                              RodKind kind) {
  const Mat3 reference = kind == RodKind::Planar ? planar_reference_frame() : Mat3::Identity();
  const Eigen::AngleAxisd rotation(Eigen::Quaterniond(R * reference.transpose()).normalized());
  OrientationTarget t{rotation.axis(), rotation.angle()};
  if (t.angle == 0.0) t.axis = Vec3::UnitZ();
  if (t.axis.z() < 0) t = {-t.axis, -t.angle};
  if (kind == RodKind::Planar && (t.axis - Vec3::UnitZ()).norm() > kFrameTolerance)
    reader.fail(v, key, "a planar rod's frame has d2 = e_z = [0, 0, 1] (d3 = [cos a, sin a, 0] the tangent)");
  return t;
}

// An orientation table: {axis = [..], angle = expr}, the reference frame turned by angle about
// axis (a planar rod's reference: d1 = e_y, d2 = e_z, d3 = e_x; a spatial rod's: the lab frame),
// or the frame itself as {matrix = ..} or directors {d1, d2, d3} (frame_from_table).
OrientationFunction orientation_target(const Reader& reader, const Value& v, const std::string& key, RodKind kind,
                                       const Parameters& parameters) {
  reader.allow_keys(v, key, {"axis", "angle", "matrix", "d1", "d2", "d3"});
  const bool axis_angle = Reader::find(v, "axis") || Reader::find(v, "angle");
  const bool directors = Reader::find(v, "d1") || Reader::find(v, "d2") || Reader::find(v, "d3");
  if (axis_angle + (Reader::find(v, "matrix") != nullptr) + directors > 1)
    reader.fail(v, key, "give one of: axis and angle, matrix, or directors d1, d2, d3");
  if (gives_frame(v)) {
    const OrientationTarget t = rotation_to(reader, v, key, frame_from_table(reader, v, key, parameters), kind);
    return [t](const Parameters&) { return t; };
  }
  const Value* axis_value = Reader::find(v, "axis");
  const Vec3 axis = axis_value ? reader.unit_vector(*axis_value, key + ".axis") : Vec3::UnitZ();
  const Value* angle_value = Reader::find(v, "angle");
  const Expression angle = angle_value ? reader.expression(*angle_value, key + ".angle") : Expression::constant(0.0);
  return [axis, angle](const Parameters& p) { return OrientationTarget{axis, angle(p)}; };
}

// The frame angles the equations can impose: in the plane, rotations about e_z; turn tracking in
// 3D counts turns about e3.
void check_rotation_axis(const Reader& reader, const Value& where, const std::string& key, const Vec3& axis,
                         RodKind kind, bool track_turns) {
  const bool along_z = std::abs(std::abs(axis.z()) - 1.0) < 1e-12;
  if (kind == RodKind::Planar && !along_z)
    reader.fail(where, key, "a planar rod only turns about e_z = [0, 0, 1]");
  if (kind == RodKind::Spatial && track_turns && (axis - Vec3::UnitZ()).norm() > 1e-12)
    reader.fail(where, key, "turns are tracked about e3 = [0, 0, 1] only");
}

// One [[obstacles]] table: the obstacle as a function of the parameters (its position and size
// may be expressions, followed by continuation), and the parameters it uses.
struct ObstacleSpec {
  std::function<Obstacle(const Parameters&)> at;
  std::set<std::string> parameters;
};

ObstacleSpec read_obstacle(const Reader& reader, const Value& o, RodKind kind, const Parameters& parameters) {
  reader.allow_keys(o, "obstacles", {"type", "name", "point", "normal", "centre", "axis", "radius", "gap", "step"});
  const Value* type_value = Reader::find(o, "type");
  const std::string type = type_value ? reader.string(*type_value, "obstacles.type") : "";
  const std::string name = Reader::find(o, "name") ? reader.string(*Reader::find(o, "name"), "obstacles.name") : "";
  auto required = [&](const char* key, const char* why) -> const Value& {
    const Value* v = Reader::find(o, key);
    if (!v) reader.fail(o, std::string("obstacles.") + key, std::string("a ") + type + " needs " + why);
    return *v;
  };
  auto refuse_others = [&](const std::set<std::string>& own) {
    for (const auto& [key, value] : o.as_table())
      if (!own.count(key) && key != "type" && key != "name")
        reader.fail(value, "obstacles." + key, "is not a key of a " + type + " (it takes: " + join(own) + ")");
  };
  ObstacleSpec spec;
  auto uses = [&](const Expression& e) {
    spec.parameters.insert(e.used_parameters().begin(), e.used_parameters().end());
  };
  if (type == "plane") {
    refuse_others({"point", "normal"});
    const Value& normal = required("normal", "a normal (towards the rod's side)");
    const Vec3 n = reader.unit_vector(normal, "obstacles.normal");
    if (kind == RodKind::Planar && std::abs(n.z()) > 1e-12)
      reader.fail(normal, "obstacles.normal", "a planar rod meets walls whose normal lies in the plane");
    const auto point = reader.vector(required("point", "a point on it"), "obstacles.point");
    for (const auto& e : point) uses(e);
    spec.at = [point = vector_target(point), n, name](const Parameters& p) { return Obstacle::plane(point(p), n, name); };
    return spec;
  }
  if (type == "cylinder") {
    refuse_others({"centre", "axis", "radius"});
    const Value* axis_value = Reader::find(o, "axis");
    const Vec3 axis = axis_value ? reader.unit_vector(*axis_value, "obstacles.axis") : Vec3::UnitZ();
    if (kind == RodKind::Planar && std::abs(std::abs(axis.z()) - 1.0) > 1e-12)
      reader.fail(*axis_value, "obstacles.axis", "a planar rod meets cylinders (discs) along e_z = [0, 0, 1]");
    const Value& radius_value = required("radius", "a radius");
    const Expression radius = reader.expression(radius_value, "obstacles.radius");
    if (!(radius(parameters) > 0))
      reader.fail(radius_value, "obstacles.radius", "must be > 0 (a sharp point is the limit of small radii)");
    const auto centre = reader.vector(required("centre", "a centre"), "obstacles.centre");
    uses(radius);
    for (const auto& e : centre) uses(e);
    spec.at = [centre = vector_target(centre), axis, radius, name](const Parameters& p) {
      return Obstacle::cylinder(centre(p), axis, radius(p), name);
    };
    return spec;
  }
  if (type == "level_set") {
    refuse_others({"gap", "step"});
    const Value& gap_value = required("gap", "a gap expression g(x, y, z), >= 0 where the rod may be");
    const Expression g = reader.position_expression(gap_value, "obstacles.gap");
    double step = 1e-3;
    if (const Value* v = Reader::find(o, "step")) {
      step = reader.number(*v, "obstacles.step");
      if (!(step > 0)) reader.fail(*v, "obstacles.step", "must be > 0");
    }
    for (const auto& n : g.used_parameters())
      if (n != "x" && n != "y" && n != "z") spec.parameters.insert(n);
    spec.at = [g, step, name](const Parameters& p) {
      Parameters at = p;
      for (const char* axis : {"x", "y", "z"}) at.set(axis, 0.0);
      const int ix = at.index_of("x");
      auto function = [g, at, ix](const Vec3& r) mutable {
        for (int i = 0; i < 3; ++i) at.value_at(ix + i) = r[i];
        return g(at);
      };
      return Obstacle::level_set(function, g.text(), name, step);
    };
    return spec;
  }
  reader.fail(type_value ? *type_value : o, "obstacles.type",
              "must be \"plane\" (a wall; two make a cavity), \"cylinder\" (a pin, indenter or rounded "
              "corner; a disc for planar rods) or \"level_set\" (any smooth gap g(x, y, z))");
}

// All [[obstacles]]: fixed, or moving with the parameters their expressions use.
void read_obstacles(const Reader& reader, const Value& list, RodKind kind, ProblemDefinition* d) {
  std::vector<std::function<Obstacle(const Parameters&)>> specs;
  for (const auto& o : reader.array(list, "obstacles", kMaxObstacles, "tables [[obstacles]]")) {
    ObstacleSpec spec = read_obstacle(reader, o, kind, d->parameters);
    try {
      d->obstacles.push_back(spec.at(d->parameters));
    } catch (const std::invalid_argument& e) {
      reader.fail(o, "obstacles", e.what());
    }
    d->obstacle_parameters.insert(spec.parameters.begin(), spec.parameters.end());
    specs.push_back(std::move(spec.at));
  }
  if (!d->obstacle_parameters.empty())
    d->moving_obstacles = [specs](const Parameters& p) {
      std::vector<Obstacle> out;
      for (const auto& at : specs) out.push_back(at(p));
      return out;
    };
}

// [[guess.contacts]]: a starting active set {obstacle = "name", s = .., force = ..}, for problems
// whose contact-free solution is admissible but not the one wanted (a rod to be found wrapped
// over an obstacle rather than beside it).
void read_contact_guesses(const Reader& reader, const Value& list, ProblemDefinition* d) {
  for (const auto& t : reader.array(list, "guess.contacts", kMaxContacts, "tables [[guess.contacts]]")) {
    reader.allow_keys(t, "guess.contacts", {"obstacle", "s", "force", "s_end", "force_end"});
    const Value* name = Reader::find(t, "obstacle");
    const Value* s = Reader::find(t, "s");
    if (!name || !s) reader.fail(t, "guess.contacts", "a contact needs the obstacle's name and an arclength s");
    const std::string wanted = reader.string(*name, "guess.contacts.obstacle");
    const auto it = std::find_if(d->obstacles.begin(), d->obstacles.end(), [&](const auto& o) { return o.name == wanted; });
    if (it == d->obstacles.end()) reader.fail(*name, "guess.contacts.obstacle", "no obstacle named '" + wanted + "'");
    PointContact c;
    c.obstacle = static_cast<int>(it - d->obstacles.begin());
    c.s = reader.value(reader.expression(*s, "guess.contacts.s"), *s, "guess.contacts.s");
    const double L = d->model(d->parameters).length;
    if (!(c.s > 0 && c.s < L)) reader.fail(*s, "guess.contacts.s", "must lie inside (0, L)");
    if (const Value* f = Reader::find(t, "force"))
      c.force = reader.value(reader.expression(*f, "guess.contacts.force"), *f, "guess.contacts.force");
    // With s_end, an extended contact over [s, s_end]: flat on a plane, wrapped around a disc.
    if (const Value* e = Reader::find(t, "s_end")) {
      c.extended = true;
      c.s_end = reader.value(reader.expression(*e, "guess.contacts.s_end"), *e, "guess.contacts.s_end");
      if (!(c.s_end > c.s && c.s_end < L)) reader.fail(*e, "guess.contacts.s_end", "must lie inside (s, L)");
      c.force_end = c.force;
      if (const Value* f = Reader::find(t, "force_end"))
        c.force_end = reader.value(reader.expression(*f, "guess.contacts.force_end"), *f, "guess.contacts.force_end");
      const RodModel model = d->model(d->parameters);
      const auto equations = d->kind == RodKind::Planar ? make_planar_equations(model) : make_spatial_equations(model);
      if (const std::string why = extended_contact_unsupported(*equations, d->obstacles[c.obstacle]); !why.empty())
        reader.fail(*e, "guess.contacts.s_end", why);
    } else if (Reader::find(t, "force_end")) {
      reader.fail(t, "guess.contacts.force_end", "is for extended contacts: give s_end too");
    }
    d->contacts.push_back(c);
  }
  std::sort(d->contacts.begin(), d->contacts.end(), [](const auto& a, const auto& b) { return a.s < b.s; });
}

EndCondition read_end(const Reader& reader, const Value& root, const std::string& name, RodKind kind,
                      const Parameters& parameters) {
  const Value* table = Reader::find(root, name);
  if (!table) reader.fail(name, "missing table [" + name + "] (the boundary condition at that end)");
  reader.allow_keys(*table, name, {"type", "position", "orientation", "track_turns", "force", "moment", "axis",
                                   "director", "rotation", "extra_angle", "extra_angle_axis", "extra_hamiltonian"});
  const Value* type_value = Reader::find(*table, "type");
  if (!type_value)
    reader.fail(*table, name + ".type", "missing (clamped, pinned, free, loaded, sliding or half_turn)");
  const std::string type = reader.string(*type_value, name + ".type");
  static const std::map<std::string, std::set<std::string>> keys_for_type = {
      {"clamped", {"position", "orientation", "track_turns"}},
      {"pinned", {"position"}},
      {"free", {}},
      {"loaded", {"force", "moment"}},
      {"sliding", {"axis", "position", "force", "orientation", "track_turns"}},
      {"half_turn", {"axis", "director", "rotation"}},
  };
  const auto it = keys_for_type.find(type);
  if (it == keys_for_type.end())
    reader.fail(*type_value, name + ".type",
                "'" + type + "' is not one of: clamped, pinned, free, loaded, sliding, half_turn");
  std::set<std::string> allowed = it->second;
  allowed.insert({"type", "extra_angle", "extra_angle_axis", "extra_hamiltonian"});
  for (const auto& [key, value] : table->as_table())
    if (!allowed.count(key))
      reader.fail(value, name + "." + key, "does not apply to a " + type + " end (allowed: " + join(allowed) + ")");

  auto vec = [&](const std::string& key) -> VectorTarget {
    const Value* v = Reader::find(*table, key);
    if (!v) return constant(Vec3::Zero());
    const auto e = reader.vector(*v, name + "." + key);
    if (kind == RodKind::Planar) {
      // Positions and forces live in the plane, moments along e_z.
      const Vec3 value(e[0](parameters), e[1](parameters), e[2](parameters));
      if (key == "moment" && (value.x() != 0.0 || value.y() != 0.0))
        reader.fail(*v, name + "." + key, "a planar rod only carries moments about e_z: give [0, 0, M]");
      if (key != "moment" && value.z() != 0.0)
        reader.fail(*v, name + "." + key, "a planar rod has no z component: give [x, y]");
    }
    return vector_target(e);
  };
  const Value* turns_value = Reader::find(*table, "track_turns");
  const bool track_turns = turns_value ? reader.boolean(*turns_value, name + ".track_turns") : false;
  auto orientation = [&]() -> OrientationFunction {
    const Value* v = Reader::find(*table, "orientation");
    if (!v) return OrientationFunction{};
    OrientationFunction f = orientation_target(reader, *v, name + ".orientation", kind, parameters);
    if (track_turns && gives_frame(*v))
      reader.fail(*v, name + ".orientation", "with track_turns, give axis and angle: a matrix or directors fix no "
                                             "count of whole turns");
    check_rotation_axis(reader, *v, name + ".orientation.axis", f(parameters).axis, kind, track_turns);
    return f;
  };

  EndCondition end;
  if (type == "clamped") {
    OrientationFunction o = orientation();
    end = EndCondition::clamped(vec("position"), o ? o : constant_orientation({}), track_turns);
  } else if (type == "pinned") {
    end = EndCondition::pinned(vec("position"));
  } else if (type == "free") {
    end = EndCondition::free();
  } else if (type == "loaded") {
    end = EndCondition::loaded(vec("force"), vec("moment"));
  } else if (type == "half_turn") {
    if (kind != RodKind::Spatial) reader.fail(*type_value, name + ".type", "a half_turn end is for spatial rods");
    if (name != "end")
      reader.fail(*type_value, name + ".type", "the half-turn symmetry point is the end s = L of the half rod");
    const Value* axis = Reader::find(*table, "axis");
    if (!axis) reader.fail(*table, name + ".axis", "a half_turn end needs the symmetry axis");
    int director = 1;
    if (const Value* d = Reader::find(*table, "director")) {
      const double value = reader.number(*d, name + ".director");
      if (value != 1.0 && value != 2.0) reader.fail(*d, name + ".director", "must be 1 or 2 (the director along the axis)");
      director = static_cast<int>(value);
    }
    std::function<double(const Parameters&)> rotation;
    if (const Value* r = Reader::find(*table, "rotation")) {
      const Expression e = reader.expression(*r, name + ".rotation");
      rotation = [e](const Parameters& p) { return e(p); };
    }
    end = EndCondition::half_turn_symmetry(reader.unit_vector(*axis, name + ".axis"), director, rotation);
  } else {
    const Value* axis = Reader::find(*table, "axis");
    if (!axis) reader.fail(*table, name + ".axis", "a sliding end needs the axis it slides along");
    end = EndCondition::sliding(reader.unit_vector(*axis, name + ".axis"), vec("position"), vec("force"),
                                orientation(), track_turns);
  }
  if (const Value* angle = Reader::find(*table, "extra_angle")) {
    const Value* axis = Reader::find(*table, "extra_angle_axis");
    const Vec3 a = axis ? reader.unit_vector(*axis, name + ".extra_angle_axis") : Vec3::UnitZ();
    if (axis) check_rotation_axis(reader, *axis, name + ".extra_angle_axis", a, kind, true);
    const Expression e = reader.expression(*angle, name + ".extra_angle");
    end.impose_orientation_angle(a, [e](const Parameters& p) { return e(p); });
  }
  if (const Value* h = Reader::find(*table, "extra_hamiltonian")) {
    const Expression e = reader.expression(*h, name + ".extra_hamiltonian");
    end.impose_hamiltonian([e](const Parameters& p) { return e(p); });
  }
  return end;
}

// The parameters a dependent one is ultimately computed from (those a user can set). Each
// parameter is visited once: rules may share inputs (a chain using the two before it would
// otherwise be walked 2^n times).
std::set<std::string> free_roots(const std::vector<DependentParameter>& dependents, const std::string& name) {
  std::set<std::string> roots, seen{name};
  std::vector<std::string> pending{name};
  while (!pending.empty()) {
    const std::string next = pending.back();
    pending.pop_back();
    const DependentParameter* d = find_dependent(dependents, next);
    if (!d) roots.insert(next);
    else
      for (const auto& used : d->uses)
        if (seen.insert(used).second) pending.push_back(used);
  }
  return roots;
}

}  // namespace

std::pair<std::string, double> parse_override(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("'" + text + "' is not NAME=VALUE");
  const std::string name = text.substr(0, eq), value = text.substr(eq + 1);
  if (!is_identifier(name))
    throw std::invalid_argument("'" + name + "' in '" + text + "' is not a parameter name (letters, digits, _)");
  // strtod rather than stod: stod throws on underflow ("1e-400" is 0 to a double, a number all
  // the same); overflow gives inf. Its range is the library's to refuse where the value is used
  // (check_overrides for --set, the run's request for an event), in the words Python's callers
  // get for the same value.
  char* end = nullptr;
  const char* begin = value.c_str();
  const double v = std::strtod(begin, &end);
  if (value.empty() || end != begin + value.size() || std::isspace(static_cast<unsigned char>(value[0])))
    throw std::invalid_argument("'" + value + "' in '" + text + "' is not a number");
  return {name, v};
}

std::string dependent_parameter_refusal(const std::vector<DependentParameter>& dependents, const std::string& name,
                                       const std::string& action) {
  if (!find_dependent(dependents, name)) return "";
  std::string roots;
  for (const auto& r : free_roots(dependents, name)) roots += (roots.empty() ? "" : ", ") + r;
  return name + " is computed from " + roots + " (an expression in [parameters]); " + action + " " + roots +
         " instead";
}

namespace {

// [parameters] entries in the order of the file: toml11 keeps a table's keys unordered, and an
// expression may use only the parameters above it.
std::vector<std::pair<std::string, const Value*>> in_file_order(const toml::table& table) {
  std::vector<std::pair<std::string, const Value*>> entries;
  for (const auto& [name, value] : table) entries.emplace_back(name, &value);
  std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    const auto &la = a.second->location(), &lb = b.second->location();
    return std::pair(la.line(), la.column()) < std::pair(lb.line(), lb.column());
  });
  return entries;
}

// A [parameters] expression: compiled against every name so that one naming a parameter below
// it is refused as such (not as an unknown variable), then checked to use only those above.
Expression parameter_expression(const Reader& plain, const Value& v, const std::string& name,
                                const std::vector<std::pair<std::string, const Value*>>& entries, std::size_t index) {
  std::vector<std::string> names;
  for (const auto& [n, value] : entries) names.push_back(n);
  std::optional<Expression> e;
  try {
    e.emplace(v.as_string().str, names, false);
  } catch (const std::invalid_argument& error) {
    plain.fail(v, "parameters." + name, error.what());
  }
  for (const auto& used : e->used_parameters()) {
    const auto at = static_cast<std::size_t>(std::find(names.begin(), names.end(), used) - names.begin());
    if (at == index) plain.fail(v, "parameters." + name, "uses itself");
    if (at > index)
      plain.fail(v, "parameters." + name,
                 "uses '" + used + "', which is given below it (line " +
                     std::to_string(entries[at].second->location().line()) +
                     "): a parameter may use only the parameters above it (so that none is computed in a cycle)");
  }
  // Bound to the names it uses only: it is evaluated wherever the problem takes its parameters.
  return Expression(v.as_string().str, e->used_parameters(), false);
}

// Reads [parameters] into values and dependent parameters, with the overrides applied to the
// parameters that are numbers. A number, or an expression using no parameter ("pi/2"), is a
// parameter of its own (it can be set and continued in); an expression of the parameters above
// it ("pi*r^2") is a DependentParameter, recomputed wherever the problem uses its parameters.
void read_parameters(const Reader& plain, const Value& root, const ParameterOverrides& overrides, Parameters* values,
                     std::vector<DependentParameter>* dependents) {
  const Value* table = Reader::find(root, "parameters");
  if (!table) return;
  if (!table->is_table()) plain.fail(*table, "parameters", "must be a table of named numbers and expressions");
  if (table->as_table().size() > static_cast<std::size_t>(kMaxParameters))
    plain.fail(*table, "parameters", "has " + std::to_string(table->as_table().size()) + " entries, at most " +
                                         std::to_string(kMaxParameters) + " are allowed");
  const auto entries = in_file_order(table->as_table());
  for (const auto& [name, value] : entries) {
    if (name == "s") plain.fail(*value, "parameters.s", "'s' is reserved for the arclength");
    if (!is_identifier(name))
      plain.fail(*value, "parameters." + name, "is not a name expressions can use (letters, digits and _)");
    const auto& reserved = reserved_constant_names();
    if (std::find(reserved.begin(), reserved.end(), name) != reserved.end())
      plain.fail(*value, "parameters." + name, "is a constant in expressions (pi = 3.14159...); name the parameter otherwise");
    values->set(name, 0.0);  // every name bound, so that each expression compiles against all of them
  }
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& [name, v] = entries[i];
    const std::string key = "parameters." + name;
    // (Clang refuses a lambda capturing a structured binding in C++17: the name by its own reference.)
    const std::string& entry_name = name;
    const auto given =
        std::find_if(overrides.begin(), overrides.end(), [&](const auto& o) { return o.first == entry_name; });
    if (!v->is_string()) {
      values->set(name, plain.number(*v, key));  // finite, within kMaxMagnitude
    } else {
      const Expression e = parameter_expression(plain, *v, name, entries, i);
      double x = 0.0;
      try {
        x = e(*values);
      } catch (const std::invalid_argument& error) {
        plain.fail(*v, key, error.what());
      }
      plain.check_magnitude(*v, key, x);
      values->set(name, x);
      if (!e.used_parameters().empty()) {
        dependents->push_back({name, [e](const Parameters& p) { return e(p); }, e.used_parameters()});
        continue;  // an override of it is refused by the caller
      }
    }
    if (given != overrides.end()) values->set(name, given->second);
  }
}
}  // namespace

Case load_case(const std::string& path, const ParameterOverrides& overrides, const std::string& phase_condition,
               const SolverOverrides& solver) {
  // Read with a cap, not by size: a FIFO or /dev/zero has none.
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CaseError(path + ": cannot open the file (" + std::strerror(errno) + ")");
  // In chunks of a few kB (a case's size), not into a buffer of the cap: zero-filling 1 MiB
  // took a quarter of the CLI's page faults.
  std::string text;
  char chunk[16384];
  while (text.size() <= kMaxFileBytes && in.read(chunk, sizeof chunk).gcount() > 0)
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
  if (in.bad()) throw CaseError(path + ": cannot read the file (" + std::strerror(errno) + ")");
  if (text.size() > kMaxFileBytes)
    throw CaseError(path + ": larger than " + std::to_string(kMaxFileBytes >> 20) + " MiB: not a case file");
  return load_case_text(text, path, overrides, phase_condition, solver);
}

Case reload_case(const Case& c, const ParameterOverrides& overrides) {
  return load_case_text(c.text, c.path, overrides, c.phase_condition, c.solver_overrides);
}

namespace {

// The raw text's limits (size, nesting depth, UTF-8), checked before toml11 sees it, then the
// TOML tree.
Value parse_case_text(const std::string& text, const std::string& path) {
  if (text.size() > kMaxFileBytes)
    throw CaseError(path + ": larger than " + std::to_string(kMaxFileBytes >> 20) + " MiB: not a case file");
  if (const int line = toml_line_beyond_nesting(text, kMaxNesting))
    throw CaseError(path + ":" + std::to_string(line) + ": arrays, inline tables and dotted keys nest deeper than " +
                    std::to_string(kMaxNesting) + " levels (a case file needs 3)");
  if (const std::size_t at = toml_invalid_utf8_at(text); at < text.size()) {
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
    throw CaseError(path + ":" + std::to_string(line) + ": not valid UTF-8 (byte " + std::to_string(at) +
                    "); a TOML file is UTF-8 text");
  }
  try {
    std::istringstream stream(text);
    return toml::parse(stream, path);
  } catch (const toml::syntax_error& e) {
    throw CaseError(path + ": TOML syntax error: " + e.what());
  } catch (const std::exception& e) {
    // toml11 reports some malformed values (out-of-range numbers, dates) with other exceptions.
    throw CaseError(path + ": TOML syntax error: " + e.what());
  }
}

// Each --set names a parameter of the file that is a number (not computed from others), with a
// finite value.
void check_overrides(const std::string& path, const Parameters& file_parameters,
                     const std::vector<DependentParameter>& dependents, const ParameterOverrides& overrides) {
  for (const auto& [name, value] : overrides) {
    if (!file_parameters.contains(name)) {
      std::set<std::string> names(file_parameters.names().begin(), file_parameters.names().end());
      throw CaseError(path + ": --set " + name + ": no parameter '" + name + "' in [parameters] (have: " +
                      join(names) + ")");
    }
    if (find_dependent(dependents, name))
      throw CaseError(path + ": --set " + name + ": " + dependent_parameter_refusal(dependents, name, "set"));
    // The one check of a --set value's range, whether the CLI parsed it or Python passed it.
    if (!std::isfinite(value) || std::abs(value) > kMaxMagnitude)
      throw CaseError(path + ": --set " + name + ": " + shown(value) + " is not a finite number with magnitude <= " +
                      shown(kMaxMagnitude));
  }
}

// [parameters] as the file gives them (*file_parameters), then with the --set overrides applied
// (returned, with the dependent parameters in *dependents).
Parameters read_parameters_with_overrides(const Reader& plain, const Value& root, const ParameterOverrides& overrides,
                                          Parameters* file_parameters, std::vector<DependentParameter>* dependents) {
  std::vector<DependentParameter> file_dependents;
  read_parameters(plain, root, {}, file_parameters, &file_dependents);
  check_overrides(plain.path(), *file_parameters, file_dependents, overrides);
  Parameters parameters;
  read_parameters(plain, root, overrides, &parameters, dependents);
  return parameters;
}

RodKind read_model_kind(const Reader& reader, const Value& root) {
  const Value* v = Reader::find(root, "model");
  if (!v) reader.fail(root, "model", "missing ('planar' or 'spatial')");
  const std::string kind = reader.string(*v, "model");
  if (kind == "planar") return RodKind::Planar;
  if (kind == "spatial") return RodKind::Spatial;
  reader.fail(*v, "model", "'" + kind + "' is not 'planar' or 'spatial'");
}

// [guess]: the state at s = 0 before the start conditions are imposed on it; its contacts go to
// d->contacts.
RodPoint read_guess(const Reader& reader, const Value& root, const Parameters& parameters, ProblemDefinition* d) {
  RodPoint guess;
  guess.R = d->kind == RodKind::Planar ? planar_reference_frame() : Mat3::Identity();
  const Value* g = Reader::find(root, "guess");
  if (!g) return guess;
  reader.allow_keys(*g, "guess", {"position", "orientation", "force", "moment", "contacts"});
  auto vec = [&](const char* key, Vec3* target) {
    if (const Value* v = Reader::find(*g, key))
      *target = vector_target(reader.vector(*v, std::string("guess.") + key))(parameters);  // checked finite
  };
  vec("position", &guess.r);
  vec("force", &guess.n);
  vec("moment", &guess.m);
  if (const Value* v = Reader::find(*g, "orientation")) {
    const OrientationTarget t = orientation_target(reader, *v, "guess.orientation", d->kind, parameters)(parameters);
    guess.R = Eigen::AngleAxisd(t.angle, t.axis).toRotationMatrix() * guess.R;
    guess.turn_angle = t.angle;
  }
  if (const Value* v = Reader::find(*g, "contacts")) read_contact_guesses(reader, *v, d);
  return guess;
}

// A level set's gap must be finite where the rod is held and where its guess starts (at
// guess_start): "1/0" compiles, and a gap that is inf everywhere is no obstacle at all, which
// would be solved and reported as if it were one.
void check_level_set_gaps(const Reader& reader, const Value& root, const Parameters& parameters,
                          const Vec3& guess_start, const ProblemDefinition& d) {
  const Value* list = Reader::find(root, "obstacles");
  if (!list) return;
  std::vector<std::pair<Vec3, std::string>> points{{guess_start, "the guess's start"}};
  for (const char* end : {"start", "end"})
    if (const Value* p = Reader::find(*Reader::find(root, end), "position"))
      points.emplace_back(vector_target(reader.vector(*p, std::string(end) + ".position"))(parameters),
                          std::string(end) + ".position");
  for (std::size_t k = 0; k < d.obstacles.size(); ++k) {
    if (d.obstacles[k].shape() != Obstacle::Shape::LevelSet) continue;
    const Value& gap = *Reader::find(list->as_array()[k], "gap");
    for (const auto& [r, where] : points) {
      std::ostringstream at;
      at << " at " << where << " (" << r.x() << ", " << r.y() << ", " << r.z() << ")";
      double g = NAN;
      try {
        g = d.obstacles[k].gap(r);
      } catch (const std::invalid_argument& e) {
        reader.fail(gap, "obstacles.gap", e.what() + at.str());
      }
      reader.check_magnitude(gap, "obstacles.gap", g, at.str());
    }
  }
}

// [output].derived: names from derived_catalogue(); the plectoneme quantities need self-contact.
std::vector<std::string> read_derived(const Reader& reader, const Value& v, const Value& root) {
  std::vector<std::string> derived = reader.strings(v, "output.derived");
  for (const auto& name : derived)
    if (!derived_catalogue().count(name)) {
      std::set<std::string> names;
      for (const auto& [n, meaning] : derived_catalogue()) names.insert(n);
      reader.fail(v, "output.derived", "'" + name + "' is not a derived quantity (known: " + join(names) + ")");
    }
  const bool self_contact = Reader::find(root, "rod") && Reader::find(*Reader::find(root, "rod"), "self_contact");
  for (const auto& q : plectoneme_quantities())
    if (!self_contact && std::find(derived.begin(), derived.end(), q.name) != derived.end())
      reader.fail(v, "output.derived", "'" + q.name + "' is a plectoneme quantity: it needs [rod.self_contact]");
  return derived;
}

// [output]: the derived quantities reported and the number of profile samples.
void read_output(const Reader& reader, const Value& root, Case* c) {
  const Value* o = Reader::find(root, "output");
  if (!o) return;
  reader.allow_keys(*o, "output", {"derived", "samples"});
  if (const Value* v = Reader::find(*o, "derived")) c->derived = read_derived(reader, *v, root);
  if (const Value* v = Reader::find(*o, "samples")) {
    c->samples = reader.integer(*v, "output.samples", 2, kMaxSamples,
                                " (1e5 samples resolve 1e-5 of the rod in a 21 MB profile)");
  }
}

// Consistency of the boundary conditions, checked by the problem itself; its message is
// attributed to the table it names.
void check_problem(const Reader& reader, const Value& root, const ProblemDefinition& d) {
  try {
    ShootingProblem check(d);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    const std::string table = what.rfind("start:", 0) == 0 ? "start" : what.rfind("end:", 0) == 0 ? "end" : "solver";
    const Value* v = Reader::find(root, table);
    if (v) reader.fail(*v, table, what);
    reader.fail(table, what);
  }
}

// The parameters the problem uses: a computed parameter it uses makes it use what that is
// computed from (later rules may use earlier ones: walked backwards).
std::set<std::string> problem_parameters(const Reader& reader, const ProblemDefinition& d) {
  std::set<std::string> used = reader.problem_uses();
  for (auto rule = d.dependent_parameters.rbegin(); rule != d.dependent_parameters.rend(); ++rule)
    if (used.count(rule->name)) used.insert(rule->uses.begin(), rule->uses.end());
  return used;
}

// Every parameter [solver] unknowns names must be used by the problem: one that no expression of
// the rod, its ends or obstacles reads could take any value (the shooting Jacobian's column is
// zero), and Newton would stop wherever it starts.
void check_unknowns_used(const Reader& reader, const Value& root, const Case& c) {
  const Value* solver = Reader::find(root, "solver");
  const Value* unknowns = solver ? Reader::find(*solver, "unknowns") : nullptr;
  if (!unknowns) return;
  for (const auto& name : reader.strings(*unknowns, "solver.unknowns"))
    if (!c.problem_parameters.count(name))
      reader.fail(*unknowns, "solver.unknowns",
                  "'" + name + "' is used by no expression of the rod, its ends or obstacles: solved for, it could "
                  "take any value. Use it where the condition it balances acts (e.g. an end's force = [\"-" + name +
                  "\", 0]), or leave it out of the unknowns");
}

}  // namespace

Case load_case_text(const std::string& text, const std::string& path, const ParameterOverrides& overrides,
                    const std::string& phase_condition, const SolverOverrides& solver) {
  // (An override given by the caller has no line in the file to name.)
  if (!phase_condition.empty() && phase_condition != "none" && phase_condition != "axial")
    throw CaseError(path + ": --phase-condition (Python: phase_condition): '" + phase_condition +
                    "' is not 'none' or 'axial'");
  Value root = parse_case_text(text, path);
  merge_solver_overrides(root, solver, path);

  Case c;
  c.path = path;
  c.text = text;
  c.overrides = overrides;
  c.phase_condition = phase_condition;
  c.solver_overrides = solver;
  // Parameters first: every expression may use them.
  const Reader plain(path, {});
  plain.allow_keys(root, "", {"title", "description", "model", "parameters", "rod", "start", "end", "guess",
                              "solver", "output", "obstacles"});
  std::vector<DependentParameter> dependents;
  const Parameters parameters = read_parameters_with_overrides(plain, root, overrides, &c.file_parameters, &dependents);
  const Reader reader(path, parameters);
  if (const Value* v = Reader::find(root, "title")) c.title = reader.string(*v, "title");
  if (const Value* v = Reader::find(root, "description")) c.description = reader.string(*v, "description");

  ProblemDefinition& d = c.definition;
  d.parameters = parameters;
  d.dependent_parameters = dependents;
  d.kind = read_model_kind(reader, root);
  read_rod(reader, root, parameters, &d);
  d.start = read_end(reader, root, "start", d.kind, parameters);
  d.end = read_end(reader, root, "end", d.kind, parameters);
  // [[obstacles]]: rigid frictionless obstacles, as gap functions g(r) >= 0.
  if (const Value* list = Reader::find(root, "obstacles")) read_obstacles(reader, *list, d.kind, &d);
  if (const Value* s = Reader::find(root, "solver")) read_solver(reader, *s, parameters, dependents, phase_condition, &d);
  if (!phase_condition.empty()) apply_phase_condition(reader, &root, phase_condition, d);
  c.start_guess = read_guess(reader, root, parameters, &d);
  check_level_set_gaps(reader, root, parameters, c.start_guess.r, d);
  read_output(reader, root, &c);
  check_problem(reader, root, d);
  c.problem_parameters = problem_parameters(reader, d);
  check_unknowns_used(reader, root, c);
  return c;
}

}  // namespace kirchhoff
