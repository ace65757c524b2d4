// [rod] of a case file: the length, the stiffness and natural-strain profiles and the external
// fields (gravity, barrier, self-contact), checked along the rod, become the problem's RodModel.
#include <deque>
#include <functional>
#include <memory>
#include <mutex>

#include "kirchhoff/contact/self_contact.hpp"
#include "kirchhoff/jobs/detail/case_reader.hpp"
#include "kirchhoff/model/detail/profile_jumps.hpp"

namespace kirchhoff::case_reading {
namespace {

// The jumps of a piecewise profile last located, with the values they were located at: a model
// is built for each new set of parameter values, and locating costs ~2e4 evaluations (3 ms), most
// of a branch's time where only a load changes. A few are kept: a finite difference alternates
// between two sets of values.
class JumpCache {
 public:
  std::vector<ProfileJump> jumps(const Profile& profile, const std::vector<double>& values) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [at, jumps] : located_)
      if (at == values) return jumps;
    if (located_.size() == kKept) located_.pop_front();
    located_.emplace_back(values, locate_jumps(profile, values.back()));
    return located_.back().second;
  }

 private:
  static constexpr size_t kKept = 4;
  std::mutex mutex_;
  // (the expression's parameters, then the rod's length; the jumps there), oldest first
  std::deque<std::pair<std::vector<double>, std::vector<ProfileJump>>> located_;
};

// A material profile: the expression, checked positive along the rod when required. One given
// piecewise (may_jump) is built with its jumps located, which the integrations land on.
struct ProfileSpec {
  Expression expression = Expression::constant(0.0);
  const Value* source = nullptr;
  std::string key;
  std::shared_ptr<JumpCache> jump_cache = std::make_shared<JumpCache>();
  Profile build(const Parameters& p, double length) const {
    if (!expression.depends_on_s()) return Profile(expression(p));
    Profile profile(expression.bind(p));
    if (!may_jump(expression.text())) return profile;
    std::vector<double> values;
    for (const auto& name : expression.used_parameters()) values.push_back(p.get(name));
    values.push_back(length);
    std::vector<ProfileJump> jumps = jump_cache->jumps(profile, values);
    return std::move(profile).with_jumps(std::move(jumps));
  }
};

// [rod]'s length and material profiles as read, before they are checked along the rod.
struct RodSpec {
  const Value* length_value = nullptr;
  Expression length = Expression::constant(0.0);
  std::array<ProfileSpec, 3> B, A, u_hat, v_hat;  // bending, shear/stretch, natural strains
  bool extensible = false;
};

// The length and the stiffness and natural-strain profiles of [rod]; unset ones take their
// defaults (unit stiffnesses, a straight unstretched rod), which have no source.
RodSpec read_rod_profiles(const Reader& reader, const Value& rod) {
  RodSpec r;
  r.length_value = Reader::find(rod, "length");
  if (!r.length_value) reader.fail(rod, "rod.length", "missing");
  r.length = reader.expression(*r.length_value, "rod.length");
  auto &B = r.B, &A = r.A, &u_hat = r.u_hat, &v_hat = r.v_hat;
  bool& extensible = r.extensible;
  const char* bend_keys[3] = {"B1", "B2", "B3"};
  const char* shear_keys[3] = {"A1", "A2", "A3"};
  const double natural_v[3] = {0.0, 0.0, 1.0};
  for (int i = 0; i < 3; ++i) {
    B[i] = {Expression::constant(1.0), nullptr, std::string("rod.") + bend_keys[i]};
    A[i] = {Expression::constant(1.0), nullptr, std::string("rod.") + shear_keys[i]};
    u_hat[i] = {Expression::constant(0.0), nullptr, "rod.u_hat"};
    v_hat[i] = {Expression::constant(natural_v[i]), nullptr, "rod.v_hat"};
  }
  if (const Value* v = Reader::find(rod, "B")) {  // isotropic bending: B1 = B2, one expression
    B[0] = {reader.expression(*v, "rod.B", true), v, "rod.B"};
    B[1] = B[0];
  }
  for (int i = 0; i < 3; ++i) {
    if (const Value* v = Reader::find(rod, bend_keys[i])) {
      const std::string key = std::string("rod.") + bend_keys[i];
      if (i < 2 && Reader::find(rod, "B")) reader.fail(*v, key, "give either B or B1/B2, not both");
      B[i] = {reader.expression(*v, key, true), v, key};
    }
    if (const Value* v = Reader::find(rod, shear_keys[i])) A[i] = {reader.expression(*v, A[i].key, true), v, A[i].key};
  }
  const Value* extensible_value = Reader::find(rod, "extensible");
  extensible = extensible_value ? reader.boolean(*extensible_value, "rod.extensible") : false;
  if (!extensible)
    for (int i = 0; i < 3; ++i)
      if (A[i].source) reader.fail(*A[i].source, A[i].key, "shear/stretch stiffness given but rod.extensible is false");
  for (auto [key, spec] : {std::pair{"u_hat", &u_hat}, std::pair{"v_hat", &v_hat}}) {
    if (const Value* v = Reader::find(rod, key)) {
      const auto e = reader.vector(*v, std::string("rod.") + key, true);
      for (int i = 0; i < 3; ++i) (*spec)[i] = {e[i], v, std::string("rod.") + key};
    }
  }
  return r;
}

// Adds the external fields to a FieldSum for the parameter values and the rod length; each
// field's reader wraps the adder built so far.
using FieldAdder = std::function<void(const Parameters&, double, FieldSum*)>;

void note_field_parameters(const Expression& e, std::set<std::string>* field_parameters) {
  for (const auto& n : e.used_parameters()) field_parameters->insert(n);
}

// A field's direction on a planar rod lies in its plane (x, y): a z component would be taken by
// the plane in silence (gravity with up = [0, 0, 1] left the rod as it was).
void refuse_out_of_plane_direction(const Reader& reader, const Value& v, const std::string& key, const Vec3& direction,
                                   RodKind kind) {
  if (kind == RodKind::Planar && direction.z() != 0.0)
    reader.fail(v, key,
                "a planar rod's field acts in its plane (x, y): the z component must be 0 (use model = \"spatial\" "
                "for a field across it)");
}

// [rod.gravity]: a uniform weight per unit length along -up (up normalised: its direction counts).
FieldAdder add_gravity(const Reader& reader, const Value& g, RodKind kind, FieldAdder prev,
                       std::set<std::string>* field_parameters) {
  reader.allow_keys(g, "rod.gravity", {"weight", "up"});
  const Value* w = Reader::find(g, "weight");
  if (!w) reader.fail(g, "rod.gravity.weight", "missing (weight per unit length)");
  const Expression weight = reader.expression(*w, "rod.gravity.weight");
  const Value* up_value = Reader::find(g, "up");
  const Vec3 up = up_value ? reader.unit_vector(*up_value, "rod.gravity.up") : Vec3::UnitY();
  if (up_value) refuse_out_of_plane_direction(reader, *up_value, "rod.gravity.up", up, kind);
  note_field_parameters(weight, field_parameters);
  return [prev = std::move(prev), weight, up](const Parameters& p, double length, FieldSum* f) {
    prev(p, length, f);
    f->add(std::make_shared<UniformGravity>(weight(p), up));
  };
}

// [rod.barrier]: a soft wall of range b and height a, normal to `normal`.
FieldAdder add_barrier(const Reader& reader, const Value& bw, RodKind kind, const Parameters& parameters,
                       FieldAdder prev, std::set<std::string>* field_parameters) {
  reader.allow_keys(bw, "rod.barrier", {"b", "a", "normal"});
  const Value* b = Reader::find(bw, "b");
  const Value* a = Reader::find(bw, "a");
  if (!b || !a) reader.fail(bw, "rod.barrier", "needs b (range) and a (wall height)");
  const Expression range = reader.expression(*b, "rod.barrier.b"), height = reader.expression(*a, "rod.barrier.a");
  const Value* normal_value = Reader::find(bw, "normal");
  const Vec3 normal = normal_value ? reader.unit_vector(*normal_value, "rod.barrier.normal") : Vec3::UnitY();
  if (normal_value) refuse_out_of_plane_direction(reader, *normal_value, "rod.barrier.normal", normal, kind);
  if (!(range(parameters) > 0)) reader.fail(*b, "rod.barrier.b", "must be > 0");
  for (const auto& e : {range, height}) note_field_parameters(e, field_parameters);
  return [prev = std::move(prev), range, height, normal](const Parameters& p, double length, FieldSum* f) {
    prev(p, length, f);
    f->add(std::make_shared<BarrierWall>(range(p), height(p), normal));
  };
}

// [rod.self_contact]: the soft self-contact of a half rod with its image under the half turn
// about `axis`; `bend` is B1, which scales the default strength.
FieldAdder add_self_contact(const Reader& reader, const Value& sc, RodKind kind, const Parameters& parameters,
                            const Expression& bend, FieldAdder prev, std::set<std::string>* field_parameters) {
  const std::string key = "rod.self_contact";
  if (kind != RodKind::Spatial) reader.fail(sc, key, "self-contact is for spatial rods");
  reader.allow_keys(sc, key, {"radius", "axis", "softness", "range", "adjacent"});
  const Value* radius_value = Reader::find(sc, "radius");
  if (!radius_value) reader.fail(sc, key + ".radius", "missing (the cross-section radius R)");
  const Expression radius = reader.expression(*radius_value, key + ".radius");
  // Defaults (see self_contact.hpp): strength b = softness B1 / R, so that the gap at the
  // pressures of a plectoneme (~0.05 B/R^3) is ~4e-4 R; the barrier decays over 0.25 R and is
  // off within 4 R of the symmetry point.
  std::optional<Expression> softness, range, adjacent;
  if (const Value* v = Reader::find(sc, "softness")) softness = reader.expression(*v, key + ".softness");
  if (const Value* v = Reader::find(sc, "range")) range = reader.expression(*v, key + ".range");
  if (const Value* v = Reader::find(sc, "adjacent")) adjacent = reader.expression(*v, key + ".adjacent");
  for (const auto* e : {&softness, &range, &adjacent})
    if (*e) note_field_parameters(**e, field_parameters);
  note_field_parameters(radius, field_parameters);
  if (!(radius(parameters) > 0)) reader.fail(*radius_value, key + ".radius", "must be > 0");
  if (softness && !((*softness)(parameters) > 0)) reader.fail(*Reader::find(sc, "softness"), key + ".softness", "must be > 0");
  const Value* axis_value = Reader::find(sc, "axis");
  const Vec3 axis = axis_value ? reader.unit_vector(*axis_value, key + ".axis") : Vec3::UnitX();
  return [prev = std::move(prev), radius, softness, range, adjacent, axis, bend](const Parameters& p, double length,
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

// The external fields of [rod] (gravity, barrier, self_contact), as one adder; the parameters
// they use go to *field_parameters.
FieldAdder read_fields(const Reader& reader, const Value& rod, RodKind kind, const Parameters& parameters,
                       const Expression& bend, std::set<std::string>* field_parameters) {
  FieldAdder add_fields = [](const Parameters&, double, FieldSum*) {};
  if (const Value* g = Reader::find(rod, "gravity"))
    add_fields = add_gravity(reader, *g, kind, add_fields, field_parameters);
  if (const Value* bw = Reader::find(rod, "barrier"))
    add_fields = add_barrier(reader, *bw, kind, parameters, add_fields, field_parameters);
  if (const Value* sc = Reader::find(rod, "self_contact"))
    add_fields = add_self_contact(reader, *sc, kind, parameters, bend, add_fields, field_parameters);
  return add_fields;
}

// Physical checks at the case's parameter values, naming the key. Expressions without s were
// checked finite when read; those with s are sampled along the rod here.
void check_rod_profiles(const Reader& reader, const RodSpec& r, const Parameters& parameters) {
  const double L = r.length(parameters);
  if (!(L > 0)) reader.fail(*r.length_value, "rod.length", "must be > 0, got " + std::to_string(L));
  for (const auto* group : {&r.B, &r.A, &r.u_hat, &r.v_hat}) {
    if (group == &r.A && !r.extensible) continue;
    const bool stiffness = group == &r.B || group == &r.A;
    for (const auto& spec : *group) {
      // Densely, and on both sides of each jump: a short stretch of a piecewise property (a
      // soft zone 1e-4 of the rod long) fell between 101 samples.
      const std::vector<double> points =
          spec.expression.depends_on_s() ? check_points(L, spec.build(parameters, L).jumps()) : std::vector<double>{0.0};
      for (const double s : points) {
        // Defaults have no source; they are constants in range.
        const double value = spec.source ? reader.value(spec.expression, *spec.source, spec.key, s) : spec.expression(parameters, s);
        if (stiffness && !(value > 0)) {
          const std::string reason = "stiffness must be > 0, got " + std::to_string(value) + " at s = " + std::to_string(s);
          if (spec.source) reader.fail(*spec.source, spec.key, reason);
          reader.fail(spec.key, reason);
        }
      }
    }
  }
}

// A planar rod bends in its plane only (about d2, stiffness B2, natural curvature u_hat[1]) and,
// when extensible, shears along d1 (A1, v_hat[0]) and stretches along d3 (A3, v_hat[2]). The
// other stiffnesses and natural strains do not enter its equations: given, they would be ignored
// in silence (a natural curvature written as u_hat = [0, 0, k] left the rod straight), so they are
// refused. A natural strain component is accepted only where it is literally zero.
void refuse_out_of_plane_properties(const Reader& reader, const Value& rod, const RodSpec& r,
                                    const Parameters& parameters) {
  for (const char* key : {"B1", "B3", "A2"})
    if (const Value* v = Reader::find(rod, key))
      reader.fail(*v, std::string("rod.") + key,
                  "a planar rod bends about d2 only (B or B2), shears along d1 (A1) and stretches along d3 (A3): " +
                      std::string(key) + " does not enter its equations (use model = \"spatial\" for it)");
  const auto must_be_zero = [&](const ProfileSpec& spec, int component, const char* what) {
    const bool zero = spec.expression.used_parameters().empty() && !spec.expression.depends_on_s() &&
                      spec.expression(parameters) == 0.0;
    if (!zero && spec.source)
      reader.fail(*spec.source, spec.key,
                  "component " + std::to_string(component + 1) + " must be 0 for a planar rod: " + what);
  };
  for (int i : {0, 2})
    must_be_zero(r.u_hat[i], i,
                 "its natural curvature is the second component, u_hat = [0, kappa, 0] (bending about d2 in the plane)");
  must_be_zero(r.v_hat[1], 1, "its natural shear is the first component and its natural stretch the third");
}

// d->model, the rod as a function of the parameters, and the parameters it uses.
void define_model(const RodSpec& r, FieldAdder add_fields, const std::set<std::string>& field_parameters,
                  ProblemDefinition* d) {
  for (const auto& n : r.length.used_parameters()) d->model_parameters.insert(n);
  for (const auto* group : {&r.B, &r.A, &r.u_hat, &r.v_hat})
    for (const auto& spec : *group)
      for (const auto& n : spec.expression.used_parameters()) d->model_parameters.insert(n);
  d->model_parameters.insert(field_parameters.begin(), field_parameters.end());
  d->model = [length = r.length, B = r.B, A = r.A, u_hat = r.u_hat, v_hat = r.v_hat, extensible = r.extensible,
              add_fields = std::move(add_fields)](const Parameters& p) {
    RodModel m;
    m.length = length(p);
    m.extensible = extensible;
    for (int i = 0; i < 3; ++i) {
      m.B[i] = B[i].build(p, m.length);
      m.A[i] = A[i].build(p, m.length);
      m.u_hat[i] = u_hat[i].build(p, m.length);
      m.v_hat[i] = v_hat[i].build(p, m.length);
    }
    auto fields = std::make_shared<FieldSum>();
    add_fields(p, m.length, fields.get());
    if (!fields->empty()) m.field = fields;
    return m;
  };
}

}  // namespace

void read_rod(const Reader& reader, const Value& root, const Parameters& parameters, ProblemDefinition* d) {
  const Value* rod = Reader::find(root, "rod");
  if (!rod) reader.fail("rod", "missing table [rod]");
  reader.allow_keys(*rod, "rod", {"length", "B", "B1", "B2", "B3", "extensible", "A1", "A2", "A3", "u_hat",
                                  "v_hat", "gravity", "barrier", "self_contact"});
  const RodSpec r = read_rod_profiles(reader, *rod);
  if (d->kind == RodKind::Planar) refuse_out_of_plane_properties(reader, *rod, r, parameters);
  std::set<std::string> field_parameters;
  FieldAdder add_fields = read_fields(reader, *rod, d->kind, parameters, r.B[0].expression, &field_parameters);
  check_rod_profiles(reader, r, parameters);
  define_model(r, std::move(add_fields), field_parameters, d);
}

}  // namespace kirchhoff::case_reading
