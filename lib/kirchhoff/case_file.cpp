#include "kirchhoff/case_file.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <toml.hpp>

#include "kirchhoff/expression.hpp"
#include "kirchhoff/plectoneme.hpp"
#include "kirchhoff/self_contact.hpp"
#include "kirchhoff/solution.hpp"

namespace kirchhoff {
namespace {

// Material properties are checked for positivity at this many points along the rod.
constexpr int kPositivitySamples = 101;

using Value = toml::value;

std::string join(const std::set<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// Reads typed values out of the TOML tree, turning every problem into a CaseError that names
// the file, the line, the key and the reason.
class Reader {
 public:
  Reader(std::string path, std::vector<std::string> parameter_names)
      : path_(std::move(path)), parameter_names_(std::move(parameter_names)) {}

  [[noreturn]] void fail(const Value& v, const std::string& key, const std::string& reason) const {
    std::ostringstream os;
    os << path_;
    const auto line = v.location().line();
    if (line > 0) os << ":" << line;
    os << ": key '" << key << "': " << reason;
    throw CaseError(os.str());
  }
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    throw CaseError(path_ + ": key '" + key + "': " + reason);
  }

  void allow_keys(const Value& table, const std::string& name, const std::set<std::string>& allowed) const {
    if (!table.is_table()) fail(table, name, "must be a table");
    for (const auto& [key, value] : table.as_table())
      if (!allowed.count(key))
        fail(value, qualified(name, key), "unknown key (expected one of: " + join(allowed) + ")");
  }

  static std::string qualified(const std::string& table, const std::string& key) {
    return table.empty() ? key : table + "." + key;
  }

  static const Value* find(const Value& table, const std::string& key) {
    if (!table.is_table()) return nullptr;
    const auto& t = table.as_table();
    const auto it = t.find(key);
    return it == t.end() ? nullptr : &it->second;
  }

  double number(const Value& v, const std::string& key) const {
    if (v.is_floating()) return v.as_floating();
    if (v.is_integer()) return static_cast<double>(v.as_integer());
    fail(v, key, "must be a number, got " + type_name(v));
  }
  long integer(const Value& v, const std::string& key) const {
    if (v.is_integer()) return static_cast<long>(v.as_integer());
    fail(v, key, "must be an integer, got " + type_name(v));
  }
  bool boolean(const Value& v, const std::string& key) const {
    if (v.is_boolean()) return v.as_boolean();
    fail(v, key, "must be true or false, got " + type_name(v));
  }
  std::string string(const Value& v, const std::string& key) const {
    if (v.is_string()) return v.as_string().str;
    fail(v, key, "must be a string, got " + type_name(v));
  }
  std::vector<std::string> strings(const Value& v, const std::string& key) const {
    if (!v.is_array()) fail(v, key, "must be an array of strings, got " + type_name(v));
    std::vector<std::string> out;
    for (const auto& e : v.as_array()) out.push_back(string(e, key));
    return out;
  }

  Expression expression(const Value& v, const std::string& key, bool uses_s = false) const {
    if (v.is_floating() || v.is_integer()) return Expression::constant(number(v, key));
    if (!v.is_string()) fail(v, key, "must be a number or an expression string, got " + type_name(v));
    try {
      return Expression(v.as_string().str, parameter_names_, uses_s);
    } catch (const std::invalid_argument& e) {
      fail(v, key, e.what());
    }
  }

  // An expression of the parameters and the position x, y, z (a level set).
  Expression position_expression(const Value& v, const std::string& key) const {
    if (!v.is_string()) fail(v, key, "must be an expression string in x, y, z, got " + type_name(v));
    std::vector<std::string> names = parameter_names_;
    for (const char* axis : {"x", "y", "z"}) {
      if (std::find(names.begin(), names.end(), axis) != names.end())
        fail(v, key, std::string("x, y and z are the position here; rename the parameter '") + axis + "'");
      names.push_back(axis);
    }
    try {
      return Expression(v.as_string().str, names, false);
    } catch (const std::invalid_argument& e) {
      fail(v, key, e.what());
    }
  }

  std::array<Expression, 3> vector(const Value& v, const std::string& key, bool uses_s = false) const {
    if (!v.is_array() || (v.as_array().size() != 3 && v.as_array().size() != 2))
      fail(v, key, "must be an array of 2 or 3 numbers/expressions");
    const auto& a = v.as_array();
    return {expression(a[0], key, uses_s), expression(a[1], key, uses_s),
            a.size() == 3 ? expression(a[2], key, uses_s) : Expression::constant(0.0)};
  }

  Vec3 unit_vector(const Value& v, const std::string& key) const {
    if (!v.is_array() || v.as_array().size() != 3) fail(v, key, "must be an array of 3 numbers");
    const auto& a = v.as_array();
    const Vec3 out(number(a[0], key), number(a[1], key), number(a[2], key));
    if (!(out.norm() > 0)) fail(v, key, "must be a non-zero vector");
    return out.normalized();
  }

  const std::string& path() const { return path_; }

 private:
  static std::string type_name(const Value& v) {
    std::ostringstream os;
    os << v.type();
    return os.str();
  }
  std::string path_;
  std::vector<std::string> parameter_names_;
};

VectorTarget vector_target(const std::array<Expression, 3>& e) {
  return [e](const Parameters& p) { return Vec3(e[0](p), e[1](p), e[2](p)); };
}

// An orientation table {axis = [..], angle = expr}.
OrientationFunction orientation_target(const Reader& reader, const Value& v, const std::string& key) {
  reader.allow_keys(v, key, {"axis", "angle"});
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
  if (!list.is_array()) reader.fail(list, "obstacles", "must be an array of tables [[obstacles]]");
  std::vector<std::function<Obstacle(const Parameters&)>> specs;
  for (const auto& o : list.as_array()) {
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
  if (!list.is_array()) reader.fail(list, "guess.contacts", "must be an array of tables [[guess.contacts]]");
  for (const auto& t : list.as_array()) {
    reader.allow_keys(t, "guess.contacts", {"obstacle", "s", "force", "s_end", "force_end"});
    const Value* name = Reader::find(t, "obstacle");
    const Value* s = Reader::find(t, "s");
    if (!name || !s) reader.fail(t, "guess.contacts", "a contact needs the obstacle's name and an arclength s");
    const std::string wanted = reader.string(*name, "guess.contacts.obstacle");
    const auto it = std::find_if(d->obstacles.begin(), d->obstacles.end(), [&](const auto& o) { return o.name == wanted; });
    if (it == d->obstacles.end()) reader.fail(*name, "guess.contacts.obstacle", "no obstacle named '" + wanted + "'");
    PointContact c;
    c.obstacle = static_cast<int>(it - d->obstacles.begin());
    c.s = reader.expression(*s, "guess.contacts.s")(d->parameters);
    const double L = d->model(d->parameters).length;
    if (!(c.s > 0 && c.s < L)) reader.fail(*s, "guess.contacts.s", "must lie inside (0, L)");
    if (const Value* f = Reader::find(t, "force")) c.force = reader.expression(*f, "guess.contacts.force")(d->parameters);
    // With s_end, an extended contact over [s, s_end]: flat on a plane, wrapped around a disc.
    if (const Value* e = Reader::find(t, "s_end")) {
      c.extended = true;
      c.s_end = reader.expression(*e, "guess.contacts.s_end")(d->parameters);
      if (!(c.s_end > c.s && c.s_end < L)) reader.fail(*e, "guess.contacts.s_end", "must lie inside (s, L)");
      c.force_end = c.force;
      if (const Value* f = Reader::find(t, "force_end"))
        c.force_end = reader.expression(*f, "guess.contacts.force_end")(d->parameters);
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
    OrientationFunction f = orientation_target(reader, *v, name + ".orientation");
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

// A material profile: the expression, checked positive along the rod when required.
struct ProfileSpec {
  Expression expression = Expression::constant(0.0);
  const Value* source = nullptr;
  std::string key;
  Profile build(const Parameters& p) const {
    return expression.depends_on_s() ? Profile(expression.bind(p)) : Profile(expression(p));
  }
};

}  // namespace

std::pair<std::string, double> parse_override(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("'" + text + "' is not NAME=VALUE");
  const std::string name = text.substr(0, eq), value = text.substr(eq + 1);
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size()) throw std::invalid_argument("'" + value + "' in '" + text + "' is not a number");
  if (!std::isfinite(v)) throw std::invalid_argument("'" + value + "' in '" + text + "' is not finite");
  return {name, v};
}

namespace {
void apply_phase_condition(const Reader& reader, const Value* where, const std::string& name, ProblemDefinition& d) {
  if (name == "axial") {
    if (d.kind != RodKind::Spatial) reader.fail(*where, "solver.phase_condition", "'axial' is for spatial rods");
    if (d.parameters.contains("unfolding"))
      reader.fail(*where, "solver.phase_condition", "needs the parameter name 'unfolding' free");
    add_axial_phase_condition(d);
  } else if (name != "none") {
    reader.fail(*where, "solver.phase_condition", "'" + name + "' is not 'none' or 'axial'");
  }
}
}  // namespace

Case load_case(const std::string& path, const ParameterOverrides& overrides, const std::string& phase_condition) {
  Value root;
  try {
    root = toml::parse(path);
  } catch (const toml::syntax_error& e) {
    throw CaseError(path + ": TOML syntax error: " + e.what());
  } catch (const std::runtime_error& e) {
    throw CaseError(path + ": " + e.what());
  }

  Case c;
  c.path = path;
  // Parameters first: every expression may use them.
  Parameters parameters;
  const Reader plain(path, {});
  plain.allow_keys(root, "", {"title", "description", "model", "parameters", "rod", "start", "end", "guess",
                              "solver", "output", "obstacles"});
  if (const Value* table = Reader::find(root, "parameters")) {
    if (!table->is_table()) plain.fail(*table, "parameters", "must be a table of named numbers");
    for (const auto& [name, value] : table->as_table()) {
      if (name == "s") plain.fail(value, "parameters.s", "'s' is reserved for the arclength");
      const double v = plain.number(value, "parameters." + name);
      if (!std::isfinite(v)) plain.fail(value, "parameters." + name, "must be a finite number");
      parameters.set(name, v);
    }
  }
  for (const auto& [name, value] : overrides) {
    if (!parameters.contains(name)) {
      std::set<std::string> names(parameters.names().begin(), parameters.names().end());
      throw CaseError(path + ": --set " + name + ": no parameter '" + name + "' in [parameters] (have: " +
                      join(names) + ")");
    }
    parameters.set(name, value);
  }
  const Reader reader(path, parameters.names());
  if (const Value* v = Reader::find(root, "title")) c.title = reader.string(*v, "title");
  if (const Value* v = Reader::find(root, "description")) c.description = reader.string(*v, "description");
  ProblemDefinition& d = c.definition;
  d.parameters = parameters;
  if (const Value* v = Reader::find(root, "model")) {
    const std::string kind = reader.string(*v, "model");
    if (kind == "planar") d.kind = RodKind::Planar;
    else if (kind == "spatial") d.kind = RodKind::Spatial;
    else reader.fail(*v, "model", "'" + kind + "' is not 'planar' or 'spatial'");
  } else {
    reader.fail(root, "model", "missing ('planar' or 'spatial')");
  }

  // [rod]
  const Value* rod = Reader::find(root, "rod");
  if (!rod) reader.fail("rod", "missing table [rod]");
  reader.allow_keys(*rod, "rod", {"length", "B", "B1", "B2", "B3", "extensible", "A1", "A2", "A3", "u_hat",
                                  "v_hat", "gravity", "barrier", "self_contact"});
  const Value* length_value = Reader::find(*rod, "length");
  if (!length_value) reader.fail(*rod, "rod.length", "missing");
  const Expression length = reader.expression(*length_value, "rod.length");
  std::array<ProfileSpec, 3> B, A, u_hat, v_hat;
  const char* bend_keys[3] = {"B1", "B2", "B3"};
  const char* shear_keys[3] = {"A1", "A2", "A3"};
  const double natural_v[3] = {0.0, 0.0, 1.0};
  for (int i = 0; i < 3; ++i) {
    B[i] = {Expression::constant(1.0), nullptr, std::string("rod.") + bend_keys[i]};
    A[i] = {Expression::constant(1.0), nullptr, std::string("rod.") + shear_keys[i]};
    u_hat[i] = {Expression::constant(0.0), nullptr, "rod.u_hat"};
    v_hat[i] = {Expression::constant(natural_v[i]), nullptr, "rod.v_hat"};
  }
  if (const Value* v = Reader::find(*rod, "B"))  // isotropic bending: B1 = B2
    for (int i = 0; i < 2; ++i) B[i] = {reader.expression(*v, "rod.B", true), v, "rod.B"};
  for (int i = 0; i < 3; ++i) {
    if (const Value* v = Reader::find(*rod, bend_keys[i])) {
      const std::string key = std::string("rod.") + bend_keys[i];
      if (i < 2 && Reader::find(*rod, "B")) reader.fail(*v, key, "give either B or B1/B2, not both");
      B[i] = {reader.expression(*v, key, true), v, key};
    }
    if (const Value* v = Reader::find(*rod, shear_keys[i])) A[i] = {reader.expression(*v, A[i].key, true), v, A[i].key};
  }
  const Value* extensible_value = Reader::find(*rod, "extensible");
  const bool extensible = extensible_value ? reader.boolean(*extensible_value, "rod.extensible") : false;
  if (!extensible)
    for (int i = 0; i < 3; ++i)
      if (A[i].source) reader.fail(*A[i].source, A[i].key, "shear/stretch stiffness given but rod.extensible is false");
  for (auto [key, spec] : {std::pair{"u_hat", &u_hat}, std::pair{"v_hat", &v_hat}}) {
    if (const Value* v = Reader::find(*rod, key)) {
      const auto e = reader.vector(*v, std::string("rod.") + key, true);
      for (int i = 0; i < 3; ++i) (*spec)[i] = {e[i], v, std::string("rod.") + key};
    }
  }
  // External fields.
  // Each adds its field for the parameter values and the rod length.
  std::function<void(const Parameters&, double, FieldSum*)> add_fields = [](const Parameters&, double, FieldSum*) {};
  std::set<std::string> field_parameters;
  if (const Value* g = Reader::find(*rod, "gravity")) {
    reader.allow_keys(*g, "rod.gravity", {"weight", "up"});
    const Value* w = Reader::find(*g, "weight");
    if (!w) reader.fail(*g, "rod.gravity.weight", "missing (weight per unit length)");
    const Expression weight = reader.expression(*w, "rod.gravity.weight");
    const Value* up_value = Reader::find(*g, "up");
    const Vec3 up = up_value ? reader.unit_vector(*up_value, "rod.gravity.up") : Vec3::UnitY();
    for (const auto& n : weight.used_parameters()) field_parameters.insert(n);
    add_fields = [prev = add_fields, weight, up](const Parameters& p, double length, FieldSum* f) {
      prev(p, length, f);
      f->add(std::make_shared<UniformGravity>(weight(p), up));
    };
  }
  if (const Value* bw = Reader::find(*rod, "barrier")) {
    reader.allow_keys(*bw, "rod.barrier", {"b", "a", "normal"});
    const Value* b = Reader::find(*bw, "b");
    const Value* a = Reader::find(*bw, "a");
    if (!b || !a) reader.fail(*bw, "rod.barrier", "needs b (range) and a (wall height)");
    const Expression range = reader.expression(*b, "rod.barrier.b"), height = reader.expression(*a, "rod.barrier.a");
    const Value* normal_value = Reader::find(*bw, "normal");
    const Vec3 normal = normal_value ? reader.unit_vector(*normal_value, "rod.barrier.normal") : Vec3::UnitY();
    if (!(range(parameters) > 0)) reader.fail(*b, "rod.barrier.b", "must be > 0");
    for (const auto& e : {range, height})
      for (const auto& n : e.used_parameters()) field_parameters.insert(n);
    add_fields = [prev = add_fields, range, height, normal](const Parameters& p, double length, FieldSum* f) {
      prev(p, length, f);
      f->add(std::make_shared<BarrierWall>(range(p), height(p), normal));
    };
  }

  if (const Value* sc = Reader::find(*rod, "self_contact")) {
    const std::string key = "rod.self_contact";
    if (d.kind != RodKind::Spatial) reader.fail(*sc, key, "self-contact is for spatial rods");
    reader.allow_keys(*sc, key, {"radius", "axis", "softness", "range", "adjacent"});
    const Value* radius_value = Reader::find(*sc, "radius");
    if (!radius_value) reader.fail(*sc, key + ".radius", "missing (the cross-section radius R)");
    const Expression radius = reader.expression(*radius_value, key + ".radius");
    // Defaults (see self_contact.hpp): strength b = softness B1 / R, so that the gap at the
    // pressures of a plectoneme (~0.05 B/R^3) is ~4e-4 R; the barrier decays over 0.25 R and is
    // off within 4 R of the symmetry point.
    std::optional<Expression> softness, range, adjacent;
    if (const Value* v = Reader::find(*sc, "softness")) softness = reader.expression(*v, key + ".softness");
    if (const Value* v = Reader::find(*sc, "range")) range = reader.expression(*v, key + ".range");
    if (const Value* v = Reader::find(*sc, "adjacent")) adjacent = reader.expression(*v, key + ".adjacent");
    for (const auto* e : {&softness, &range, &adjacent})
      if (*e) for (const auto& n : (*e)->used_parameters()) field_parameters.insert(n);
    for (const auto& n : radius.used_parameters()) field_parameters.insert(n);
    if (!(radius(parameters) > 0)) reader.fail(*radius_value, key + ".radius", "must be > 0");
    if (softness && !((*softness)(parameters) > 0)) reader.fail(*Reader::find(*sc, "softness"), key + ".softness", "must be > 0");
    const Value* axis_value = Reader::find(*sc, "axis");
    const Vec3 axis = axis_value ? reader.unit_vector(*axis_value, key + ".axis") : Vec3::UnitX();
    const Expression bend = B[0].expression;
    add_fields = [prev = add_fields, radius, softness, range, adjacent, axis, bend](const Parameters& p, double length,
                                                                                  FieldSum* f) {
      prev(p, length, f);
      HalfTurnSelfContactOptions o;
      o.radius = radius(p);
      o.axis = axis;
      o.symmetry_s = length;
      o.strength = (softness ? (*softness)(p) : 1e-8) * bend(p, 0.0) / o.radius;
      o.range = range ? (*range)(p) : 0.25 * o.radius;
      o.adjacent = adjacent ? (*adjacent)(p) : 4.0 * o.radius;
      f->add(std::make_shared<HalfTurnSelfContact>(o));
    };
  }

  // Physical checks at the case's parameter values, naming the key.
  const double L = length(parameters);
  if (!(L > 0)) reader.fail(*length_value, "rod.length", "must be > 0, got " + std::to_string(L));
  for (const auto* group : {&B, &A}) {
    if (group == &A && !extensible) continue;
    for (const auto& spec : *group) {
      for (int k = 0; k < kPositivitySamples; ++k) {
        const double s = L * k / (kPositivitySamples - 1);
        const double value = spec.expression(parameters, s);
        if (!(value > 0)) {
          const std::string reason = "stiffness must be > 0, got " + std::to_string(value) + " at s = " + std::to_string(s);
          if (spec.source) reader.fail(*spec.source, spec.key, reason);
          reader.fail(spec.key, reason);
        }
        if (!spec.expression.depends_on_s()) break;
      }
    }
  }

  for (const auto* e : {&length})
    for (const auto& n : e->used_parameters()) d.model_parameters.insert(n);
  for (const auto* group : {&B, &A, &u_hat, &v_hat})
    for (const auto& spec : *group)
      for (const auto& n : spec.expression.used_parameters()) d.model_parameters.insert(n);
  d.model_parameters.insert(field_parameters.begin(), field_parameters.end());
  d.model = [length, B, A, u_hat, v_hat, extensible, add_fields](const Parameters& p) {
    RodModel m;
    m.length = length(p);
    m.extensible = extensible;
    for (int i = 0; i < 3; ++i) {
      m.B[i] = B[i].build(p);
      m.A[i] = A[i].build(p);
      m.u_hat[i] = u_hat[i].build(p);
      m.v_hat[i] = v_hat[i].build(p);
    }
    auto fields = std::make_shared<FieldSum>();
    add_fields(p, m.length, fields.get());
    if (!fields->empty()) m.field = fields;
    return m;
  };

  d.start = read_end(reader, root, "start", d.kind, parameters);
  d.end = read_end(reader, root, "end", d.kind, parameters);

  // [[obstacles]]: rigid frictionless obstacles, as gap functions g(r) >= 0.
  if (const Value* list = Reader::find(root, "obstacles")) read_obstacles(reader, *list, d.kind, &d);

  // [solver]
  if (const Value* s = Reader::find(root, "solver")) {
    reader.allow_keys(*s, "solver", {"unknowns", "segments", "stepper", "abs_tol", "rel_tol", "sensitivity_tol",
                                     "tolerance", "max_iterations", "jacobian", "fallback_search", "phase_condition",
                                     "threads"});
    ShootingOptions& o = d.options;
    if (const Value* v = Reader::find(*s, "unknowns")) {
      d.unknown_parameters = reader.strings(*v, "solver.unknowns");
      for (const auto& name : d.unknown_parameters)
        if (!parameters.contains(name))
          reader.fail(*v, "solver.unknowns", "'" + name + "' is not in [parameters] (give it there with a guess)");
    }
    if (const Value* v = Reader::find(*s, "segments")) {
      // An integer, or an expression of the parameters rounded (e.g. "slenderness / 5": long
      // slender rods need more segments) evaluated at load time.
      o.segments = v->is_string() ? static_cast<int>(std::lround(reader.expression(*v, "solver.segments")(parameters)))
                                  : static_cast<int>(reader.integer(*v, "solver.segments"));
      if (o.segments < 1) reader.fail(*v, "solver.segments", "must be >= 1");
      if (o.segments > 1 && !d.obstacles.empty())
        reader.fail(*v, "solver.segments", "contact with obstacles needs single shooting (segments = 1)");
    }
    if (const Value* v = Reader::find(*s, "threads")) {
      o.threads = static_cast<int>(reader.integer(*v, "solver.threads"));
      if (o.threads < 0) reader.fail(*v, "solver.threads", "must be >= 0 (0: the machine's hardware concurrency)");
    }
    if (const Value* v = Reader::find(*s, "stepper")) {
      const std::string name = reader.string(*v, "solver.stepper");
      if (name == "rk78") o.integrator.stepper = IntegratorOptions::Stepper::RungeKutta78;
      else if (name == "dopri5") o.integrator.stepper = IntegratorOptions::Stepper::Dopri5;
      else reader.fail(*v, "solver.stepper", "'" + name + "' is not 'rk78' or 'dopri5'");
    }
    auto positive = [&](const char* key, double* target) {
      if (const Value* v = Reader::find(*s, key)) {
        *target = reader.number(*v, std::string("solver.") + key);
        if (!(*target > 0)) reader.fail(*v, std::string("solver.") + key, "must be > 0");
      }
    };
    positive("abs_tol", &o.integrator.abs_tol);
    positive("rel_tol", &o.integrator.rel_tol);
    positive("sensitivity_tol", &o.integrator.sensitivity_tol);
    positive("tolerance", &o.newton.residual_tolerance);
    if (const Value* v = Reader::find(*s, "max_iterations")) {
      o.newton.max_iterations = static_cast<int>(reader.integer(*v, "solver.max_iterations"));
      if (o.newton.max_iterations < 1) reader.fail(*v, "solver.max_iterations", "must be >= 1");
    }
    if (const Value* v = Reader::find(*s, "jacobian")) {
      const std::string name = reader.string(*v, "solver.jacobian");
      if (name == "finite_differences") o.newton.finite_difference_jacobian = true;
      else if (name != "variational") reader.fail(*v, "solver.jacobian", "'" + name + "' is not 'variational' or 'finite_differences'");
    }
    if (const Value* v = Reader::find(*s, "fallback_search")) o.newton.fallback_search = reader.boolean(*v, "solver.fallback_search");
    if (const Value* v = Reader::find(*s, "phase_condition"); v && phase_condition.empty())
      apply_phase_condition(reader, v, reader.string(*v, "solver.phase_condition"), d);
  }

  if (!phase_condition.empty()) apply_phase_condition(reader, &root, phase_condition, d);

  // [guess]: the state at s = 0 before the start conditions are imposed on it.
  c.start_guess.R = d.kind == RodKind::Planar ? planar_reference_frame() : Mat3::Identity();
  if (const Value* g = Reader::find(root, "guess")) {
    reader.allow_keys(*g, "guess", {"position", "orientation", "force", "moment", "contacts"});
    auto vec = [&](const char* key, Vec3* target) {
      if (const Value* v = Reader::find(*g, key)) *target = vector_target(reader.vector(*v, std::string("guess.") + key))(parameters);
    };
    vec("position", &c.start_guess.r);
    vec("force", &c.start_guess.n);
    vec("moment", &c.start_guess.m);
    if (const Value* v = Reader::find(*g, "orientation")) {
      const OrientationTarget t = orientation_target(reader, *v, "guess.orientation")(parameters);
      c.start_guess.R = Eigen::AngleAxisd(t.angle, t.axis).toRotationMatrix() * c.start_guess.R;
      c.start_guess.turn_angle = t.angle;
    }
    if (const Value* v = Reader::find(*g, "contacts")) read_contact_guesses(reader, *v, &d);
  }

  // [output]
  if (const Value* o = Reader::find(root, "output")) {
    reader.allow_keys(*o, "output", {"derived", "samples"});
    if (const Value* v = Reader::find(*o, "derived")) {
      c.derived = reader.strings(*v, "output.derived");
      for (const auto& name : c.derived)
        if (!derived_catalogue().count(name)) {
          std::set<std::string> names;
          for (const auto& [n, meaning] : derived_catalogue()) names.insert(n);
          reader.fail(*v, "output.derived", "'" + name + "' is not a derived quantity (known: " + join(names) + ")");
        }
      const bool self_contact = Reader::find(root, "rod") && Reader::find(*Reader::find(root, "rod"), "self_contact");
      for (const auto& [name, meaning] : plectoneme_quantities())
        if (!self_contact && std::find(c.derived.begin(), c.derived.end(), name) != c.derived.end())
          reader.fail(*v, "output.derived", "'" + name + "' is a plectoneme quantity: it needs [rod.self_contact]");
    }
    if (const Value* v = Reader::find(*o, "samples")) {
      c.samples = static_cast<int>(reader.integer(*v, "output.samples"));
      if (c.samples < 2) reader.fail(*v, "output.samples", "must be >= 2");
    }
  }

  // Consistency of the boundary conditions, checked by the problem itself.
  try {
    ShootingProblem check(d);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    const std::string table = what.rfind("start:", 0) == 0 ? "start" : what.rfind("end:", 0) == 0 ? "end" : "solver";
    const Value* v = Reader::find(root, table);
    if (v) reader.fail(*v, table, what);
    reader.fail(table, what);
  }
  return c;
}

}  // namespace kirchhoff
