#include "kirchhoff/case_file.hpp"

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

#include "kirchhoff/expression.hpp"
#include "kirchhoff/plectoneme.hpp"
#include "kirchhoff/self_contact.hpp"
#include "kirchhoff/solution.hpp"
#include "kirchhoff/toml_nesting.hpp"

namespace kirchhoff {
namespace {

// Material properties are checked (positive, finite) at this many points along the rod.
constexpr int kPositivitySamples = 101;

using Value = toml::value;
using namespace case_limits;

// "1e+100" rather than std::to_string's "10000000000...".
std::string shown(double v) {
  std::ostringstream os;
  os.precision(15);  // whole numbers up to 1e15 exactly (4294967297, not 4.29497e+09)
  os << v;
  return os.str();
}


std::string join(const std::set<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// Values given on the command line (--solver KEY=VALUE) are parsed under this source name, so
// that messages name the option instead of a line of the file.
constexpr const char* kSolverOption = "--solver ";
bool is_command_line(const Value& v) { return v.location().file_name().rfind(kSolverOption, 0) == 0; }

// Reads typed values out of the TOML tree, turning every problem into a CaseError that names
// the file, the line, the key and the reason.
class Reader {
 public:
  // Expressions may use the parameters, and are checked at their values.
  Reader(std::string path, Parameters parameters)
      : path_(std::move(path)), parameter_names_(parameters.names()), parameters_(std::move(parameters)) {}

  [[noreturn]] void fail(const Value& v, const std::string& key, const std::string& reason) const {
    std::ostringstream os;
    os << path_;
    const auto line = v.location().line();
    if (is_command_line(v)) os << ": " << v.location().file_name();  // "--solver tolerance=..."
    else if (line > 0) os << ":" << line;
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

  // TOML allows inf and nan; no quantity of a rod may be either, or beyond kMaxMagnitude.
  double number(const Value& v, const std::string& key) const {
    double x = 0.0;
    if (v.is_floating()) x = v.as_floating();
    else if (v.is_integer()) x = static_cast<double>(v.as_integer());
    else fail(v, key, "must be a number, got " + type_name(v));
    check_magnitude(v, key, x);
    return x;
  }
  void check_magnitude(const Value& v, const std::string& key, double x, const std::string& where = "") const {
    if (!std::isfinite(x)) fail(v, key, "must be a finite number, got " + shown(x) + where);
    if (std::abs(x) > kMaxMagnitude)
      fail(v, key, "must have a magnitude <= " + shown(kMaxMagnitude) + " (so that the equations' products do not "
                   "overflow), got " + shown(x) + where);
  }
  // An integer in [low, high], checked before it is narrowed to int: a TOML integer has 64 bits,
  // and 9223372036854775807 must be refused, not wrapped. `why` says where the bound comes from.
  int integer(const Value& v, const std::string& key, long low, long high, const std::string& why = "") const {
    if (!v.is_integer()) fail(v, key, "must be an integer, got " + type_name(v));
    return in_range(v, key, static_cast<double>(v.as_integer()), low, high, why, std::to_string(v.as_integer()));
  }
  int in_range(const Value& v, const std::string& key, double x, long low, long high, const std::string& why,
               const std::string& as_given = "") const {
    if (!(x >= static_cast<double>(low) && x <= static_cast<double>(high)))
      fail(v, key, "must be in [" + std::to_string(low) + ", " + std::to_string(high) + "]" + why + ", got " +
                       (as_given.empty() ? shown(x) : as_given));
    return static_cast<int>(x);
  }
  // A value in (0, kMaxTolerance].
  double tolerance(const Value& v, const std::string& key) const {
    double x = 0.0;
    if (v.is_floating()) x = v.as_floating();
    else if (v.is_integer()) x = static_cast<double>(v.as_integer());
    else fail(v, key, "must be a number, got " + type_name(v));
    if (!(x > 0 && x <= kMaxTolerance))  // also refuses nan and inf
      fail(v, key, "must be in (0, " + shown(kMaxTolerance) + "] (a looser tolerance gives answers wrong in the "
                   "second digit), got " + shown(x));
    return x;
  }
  // An array of at most `most` entries.
  const toml::array& array(const Value& v, const std::string& key, int most, const std::string& what) const {
    if (!v.is_array()) fail(v, key, "must be an array of " + what + ", got " + type_name(v));
    if (v.as_array().size() > static_cast<std::size_t>(most))
      fail(v, key, "has " + std::to_string(v.as_array().size()) + " entries, at most " + std::to_string(most) +
                       " are allowed");
    return v.as_array();
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
    std::vector<std::string> out;
    for (const auto& e : array(v, key, kMaxNames, "strings")) out.push_back(string(e, key));
    return out;
  }

  // An expression of the parameters (and of s when uses_s). One that does not use s is also
  // evaluated here, at the case's parameter values, and refused unless finite and within
  // kMaxMagnitude ("1/0", "exp(1000)", "1e60 * 1e60"); material profiles are checked along the
  // rod once its length is known.
  Expression expression(const Value& v, const std::string& key, bool uses_s = false) const {
    if (v.is_floating() || v.is_integer()) return Expression::constant(number(v, key));
    if (!v.is_string()) fail(v, key, "must be a number or an expression string, got " + type_name(v));
    std::optional<Expression> e;
    try {
      e.emplace(v.as_string().str, parameter_names_, uses_s);
    } catch (const std::invalid_argument& error) {
      fail(v, key, error.what());
    }
    if (!e->depends_on_s()) (void)value(*e, v, key);
    note_uses(*e, key);
    return *e;
  }

  // The parameters the problem itself (not its [guess]) depends on, as far as read so far.
  const std::set<std::string>& problem_uses() const { return problem_uses_; }

  // e at the case's parameter values and arclength s: finite and within kMaxMagnitude.
  double value(const Expression& e, const Value& v, const std::string& key, double s = 0.0) const {
    double x = 0.0;
    try {
      x = e(parameters_, s);
    } catch (const std::invalid_argument& error) {
      fail(v, key, error.what());
    }
    check_magnitude(v, key, x, e.depends_on_s() ? " at s = " + shown(s) : "");
    return x;
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
      Expression e(v.as_string().str, names, false);
      note_uses(e, key);
      return e;
    } catch (const std::invalid_argument& e) {
      fail(v, key, e.what());
    }
  }

  void note_uses(const Expression& e, const std::string& key) const {
    if (key.rfind("guess", 0) == 0) return;
    problem_uses_.insert(e.used_parameters().begin(), e.used_parameters().end());
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
  Parameters parameters_;
  mutable std::set<std::string> problem_uses_;  // see uses()
};

VectorTarget vector_target(const std::array<Expression, 3>& e) {
  return [e](const Parameters& p) { return Vec3(e[0](p), e[1](p), e[2](p)); };
}

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

namespace {

// A parameter name muParser can bind: a letter or '_', then letters, digits and '_'.
bool is_identifier(const std::string& name) {
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
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
  // the same); overflow gives inf, refused below with the other non-finite values.
  char* end = nullptr;
  const char* begin = value.c_str();
  const double v = std::strtod(begin, &end);
  if (value.empty() || end != begin + value.size() || std::isspace(static_cast<unsigned char>(value[0])))
    throw std::invalid_argument("'" + value + "' in '" + text + "' is not a number");
  if (!std::isfinite(v)) throw std::invalid_argument("'" + value + "' in '" + text + "' is not finite");
  if (std::abs(v) > case_limits::kMaxMagnitude)
    throw std::invalid_argument("'" + value + "' in '" + text + "' is out of range (|value| <= " +
                                shown(case_limits::kMaxMagnitude) + ")");
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

// A --solver value as TOML ("1e-10", "true", "[\"P\"]"); text that is not one TOML value (rk78)
// is the string it spells. Either carries the option as its source, for messages.
Value solver_value(const std::string& path, const std::string& key, const std::string& text) {
  const std::string source = kSolverOption + key + "=" + text;
  auto parsed = [&](const std::string& toml_text) -> std::optional<Value> {
    try {
      std::istringstream in("value = " + toml_text);
      const Value table = toml::parse(in, source);
      if (table.as_table().size() == 1) return table.as_table().at("value");
    } catch (const std::exception&) {
    }
    return std::nullopt;
  };
  if (auto v = parsed(text)) return *v;
  std::string quoted = "\"";
  for (const char ch : text) {
    if (ch == '"' || ch == '\\') quoted += '\\';
    if (static_cast<unsigned char>(ch) < 0x20) throw CaseError(path + ": " + source + ": control characters in the value");
    quoted += ch;
  }
  if (auto v = parsed(quoted + "\"")) return *v;
  throw CaseError(path + ": " + source + ": neither a TOML value nor a string");
}

// --solver KEY=VALUE in place of [solver] KEY, so that each is validated, and refused, exactly
// as the file's own value would be.
void merge_solver_overrides(Value& root, const SolverOverrides& solver, const std::string& path) {
  if (solver.empty()) return;
  auto& table = root.as_table();
  if (!table.count("solver")) table["solver"] = toml::table{};
  Value& solver_table = table["solver"];
  if (!solver_table.is_table()) return;  // refused as the file's [solver] when read
  for (const auto& [key, text] : solver) solver_table.as_table()[key] = solver_value(path, key, text);
}

}  // namespace

std::pair<std::string, std::string> parse_solver_override(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw std::invalid_argument("'" + text + "' is not KEY=VALUE (a [solver] key and its value, e.g. tolerance=1e-10)");
  const std::string key = text.substr(0, eq);
  if (!is_identifier(key)) throw std::invalid_argument("'" + key + "' in '" + text + "' is not a [solver] key");
  return {key, text.substr(eq + 1)};
}

SolverOverrides parse_solver_overrides(const std::vector<std::string>& texts) {
  SolverOverrides out;
  for (const auto& t : texts) {
    try {
      out.push_back(parse_solver_override(t));
    } catch (const std::invalid_argument& e) {
      throw CaseError(std::string("--solver ") + e.what());
    }
  }
  return out;
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
  std::string text(kMaxFileBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw CaseError(path + ": cannot read the file (" + std::strerror(errno) + ")");
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxFileBytes)
    throw CaseError(path + ": larger than " + std::to_string(kMaxFileBytes >> 20) + " MiB: not a case file");
  return load_case_text(text, path, overrides, phase_condition, solver);
}

Case reload_case(const Case& c, const ParameterOverrides& overrides) {
  return load_case_text(c.text, c.path, overrides, c.phase_condition, c.solver_overrides);
}

Case load_case_text(const std::string& text, const std::string& path, const ParameterOverrides& overrides,
                    const std::string& phase_condition, const SolverOverrides& solver) {
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
  Value root;
  try {
    std::istringstream stream(text);
    root = toml::parse(stream, path);
  } catch (const toml::syntax_error& e) {
    throw CaseError(path + ": TOML syntax error: " + e.what());
  } catch (const std::exception& e) {
    // toml11 reports some malformed values (out-of-range numbers, dates) with other exceptions.
    throw CaseError(path + ": TOML syntax error: " + e.what());
  }

  merge_solver_overrides(root, solver, path);

  Case c;
  c.path = path;
  c.solver_overrides = solver;
  // Parameters first: every expression may use them.
  Parameters parameters;
  const Reader plain(path, {});
  plain.allow_keys(root, "", {"title", "description", "model", "parameters", "rod", "start", "end", "guess",
                              "solver", "output", "obstacles"});
  std::vector<DependentParameter> dependents;
  read_parameters(plain, root, {}, &c.file_parameters, &dependents);
  c.overrides = overrides;
  c.text = text;
  c.phase_condition = phase_condition;
  for (const auto& [name, value] : overrides) {
    if (!c.file_parameters.contains(name)) {
      std::set<std::string> names(c.file_parameters.names().begin(), c.file_parameters.names().end());
      throw CaseError(path + ": --set " + name + ": no parameter '" + name + "' in [parameters] (have: " +
                      join(names) + ")");
    }
    if (find_dependent(dependents, name))
      throw CaseError(path + ": --set " + name + ": " + dependent_parameter_refusal(dependents, name, "set"));
    // The CLI's parse_override checks this too; load_case is also called with overrides directly.
    if (!std::isfinite(value) || std::abs(value) > kMaxMagnitude)
      throw CaseError(path + ": --set " + name + ": " + shown(value) + " is not a finite number with magnitude <= " +
                      shown(kMaxMagnitude));
  }
  dependents.clear();
  read_parameters(plain, root, overrides, &parameters, &dependents);
  const Reader reader(path, parameters);
  if (const Value* v = Reader::find(root, "title")) c.title = reader.string(*v, "title");
  if (const Value* v = Reader::find(root, "description")) c.description = reader.string(*v, "description");
  ProblemDefinition& d = c.definition;
  d.parameters = parameters;
  d.dependent_parameters = dependents;
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

  // Physical checks at the case's parameter values, naming the key. Expressions without s were
  // checked finite when read; those with s are sampled along the rod here.
  const double L = length(parameters);
  if (!(L > 0)) reader.fail(*length_value, "rod.length", "must be > 0, got " + std::to_string(L));
  for (const auto* group : {&B, &A, &u_hat, &v_hat}) {
    if (group == &A && !extensible) continue;
    const bool stiffness = group == &B || group == &A;
    for (const auto& spec : *group) {
      for (int k = 0; k < kPositivitySamples; ++k) {
        const double s = L * k / (kPositivitySamples - 1);
        // Defaults have no source; they are constants in range.
        const double value = spec.source ? reader.value(spec.expression, *spec.source, spec.key, s) : spec.expression(parameters, s);
        if (stiffness && !(value > 0)) {
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
      for (const auto& name : d.unknown_parameters) {
        if (!parameters.contains(name))
          reader.fail(*v, "solver.unknowns", "'" + name + "' is not in [parameters] (give it there with a guess)");
        if (find_dependent(dependents, name))
          reader.fail(*v, "solver.unknowns", dependent_parameter_refusal(dependents, name, "solve for"));
      }
    }
    if (const Value* v = Reader::find(*s, "segments")) {
      // An integer, or an expression of the parameters rounded (e.g. "slenderness / 5": long
      // slender rods need more segments) evaluated at load time. Either is range-checked
      // before it becomes an int ("1e10" once wrapped to -129542143).
      const std::string why = " (Newton's Jacobian is dense: 13 x segments unknowns squared)";
      if (v->is_string()) {
        const double x = reader.value(reader.expression(*v, "solver.segments"), *v, "solver.segments");
        o.segments = reader.in_range(*v, "solver.segments", std::round(x), 1, kMaxSegments, why);
      } else {
        o.segments = reader.integer(*v, "solver.segments", 1, kMaxSegments, why);
      }
      if (o.segments > 1 && !d.obstacles.empty())
        reader.fail(*v, "solver.segments", "contact with obstacles needs single shooting (segments = 1)");
    }
    if (const Value* v = Reader::find(*s, "threads")) {
      o.threads = reader.integer(*v, "solver.threads", 0, kMaxThreads, " (0: the machine's hardware concurrency)");
    }
    if (const Value* v = Reader::find(*s, "stepper")) {
      const std::string name = reader.string(*v, "solver.stepper");
      if (name == "rk78") o.integrator.stepper = IntegratorOptions::Stepper::RungeKutta78;
      else if (name == "dopri5") o.integrator.stepper = IntegratorOptions::Stepper::Dopri5;
      else reader.fail(*v, "solver.stepper", "'" + name + "' is not 'rk78' or 'dopri5'");
    }
    auto positive = [&](const char* key, double* target) {
      if (const Value* v = Reader::find(*s, key)) *target = reader.tolerance(*v, std::string("solver.") + key);
    };
    positive("abs_tol", &o.integrator.abs_tol);
    positive("rel_tol", &o.integrator.rel_tol);
    positive("sensitivity_tol", &o.integrator.sensitivity_tol);
    positive("tolerance", &o.newton.residual_tolerance);
    if (const Value* v = Reader::find(*s, "max_iterations")) {
      o.newton.max_iterations = reader.integer(*v, "solver.max_iterations", 1, kMaxIterations,
                                               " (each iteration forms a Jacobian; Newton converges in tens)");
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
      if (const Value* v = Reader::find(*g, key))
        *target = vector_target(reader.vector(*v, std::string("guess.") + key))(parameters);  // checked finite
    };
    vec("position", &c.start_guess.r);
    vec("force", &c.start_guess.n);
    vec("moment", &c.start_guess.m);
    if (const Value* v = Reader::find(*g, "orientation")) {
      const OrientationTarget t = orientation_target(reader, *v, "guess.orientation", d.kind, parameters)(parameters);
      c.start_guess.R = Eigen::AngleAxisd(t.angle, t.axis).toRotationMatrix() * c.start_guess.R;
      c.start_guess.turn_angle = t.angle;
    }
    if (const Value* v = Reader::find(*g, "contacts")) read_contact_guesses(reader, *v, &d);
  }

  // A level set's gap must be finite where the rod is held and where its guess starts: "1/0"
  // compiles, and a gap that is inf everywhere is no obstacle at all, which would be solved and
  // reported as if it were one.
  if (const Value* list = Reader::find(root, "obstacles")) {
    std::vector<std::pair<Vec3, std::string>> points{{c.start_guess.r, "the guess's start"}};
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
      c.samples = reader.integer(*v, "output.samples", 2, kMaxSamples,
                                 " (1e5 samples resolve 1e-5 of the rod in a 21 MB profile)");
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
  // A computed parameter the problem uses makes the problem use what it is computed from (later
  // rules may use earlier ones: walked backwards).
  c.problem_parameters = reader.problem_uses();
  for (auto rule = d.dependent_parameters.rbegin(); rule != d.dependent_parameters.rend(); ++rule)
    if (c.problem_parameters.count(rule->name)) c.problem_parameters.insert(rule->uses.begin(), rule->uses.end());
  return c;
}

}  // namespace kirchhoff
