// Jolt Physics, compiled natively from its C++ source, driven over line-delimited JSON: the program behind the
// benchmark's jolt-native peers (bench/peers/jolt_native_world.py, built by bench/peers/jolt_build.py).
//
//     jolt_driver [--threads N]    N = 1 (the default): Jolt's JobSystemSingleThreaded, every job run on the
//                                  stepping thread; N > 1: a JobSystemThreadPool of N - 1 workers, the stepping
//                                  thread running jobs too while it waits for them (N threads in all)
//
// It speaks the protocol of bench/peers/wasm/driver.mjs, one answer line per request line:
//     {"op": "build", "dt": s, "gravity": [x, y, z], "sleeping": bool, "shapes": [...], "bodies": [...],
//      "joints": [...]}  ->  {"version": "..."}
//     {"op": "step", "n": k, "budget": s or null}  ->  {"seconds": [...]}  the time of each step (s), measured
//         here (std::chrono::steady_clock) around PhysicsSystem::Update alone; stops early once they add up to
//         more than the budget
//     {"op": "positions"}  ->  {"positions": [x0, y0, z0, x1, ...]}  dynamic bodies in build order (m)
//     {"op": "orientations"}  ->  {"orientations": [w0, x0, y0, z0, w1, ...]}  the same bodies' (unit quaternions)
//     {"op": "penetration"}  ->  {"depth": d}  deepest overlap among the current contacts (m, 0 if none)
//     {"op": "echo", "value": v}  ->  {"value": v}  (for the tests of this file's JSON reader and writer)
//     {"op": "close"}  ->  the process exits
// A request that fails is answered {"error": "message"} and the process exits with status 1.  Jolt's traces go to
// stderr, never into the answers.
//
// Jolt is set up as bench/peers/wasm/jolt.mjs sets up its WebAssembly build, so that the two differ in how Jolt
// is compiled and threaded, not in what it computes: the sizes of jolt-physics' JoltInterface (room for 10,240
// bodies, or the scene's, 65,536 body pairs, 10,240 contact constraints, a 10 MB temporary allocator); two object
// layers, static and moving, each in a broad-phase layer of its own, moving bodies colliding with both; Jolt's
// defaults otherwise (10 velocity and 2 position iterations, sleeping unless the build says not, speculative
// contacts); no damping, no cap
// on linear speed; the mass given, the inertia computed from the shape; each body's own friction and restitution
// (Jolt combines them by geometric mean and maximum, as Marbellous does); a ball joint as Jolt's point
// constraint, its two points on the anchor, the two bodies kept from colliding with each other as in Marbellous
// (each set of bodies that joints join is a collision group in which a joined pair does not collide; the same in
// jolt.mjs).  One Update with one collision step
// per step.  One difference: a step whose Update reports a full contact, manifold or body-pair buffer (Jolt then
// drops contacts and bodies sink into each other) fails, where the WebAssembly backend, which cannot see that
// report, counts the pairs in contact at each sample instead.
#include <Jolt/Jolt.h>

#include <Jolt/Core/Factory.h>
#include <Jolt/Core/JobSystemSingleThreaded.h>
#include <Jolt/Core/JobSystemThreadPool.h>
#include <Jolt/Core/TempAllocator.h>
#include <Jolt/Physics/Body/BodyCreationSettings.h>
#include <Jolt/Physics/Body/BodyFilter.h>
#include <Jolt/Physics/Collision/BroadPhase/BroadPhaseLayerInterfaceTable.h>
#include <Jolt/Physics/Collision/BroadPhase/ObjectVsBroadPhaseLayerFilterTable.h>
#include <Jolt/Physics/Collision/CollideShape.h>
#include <Jolt/Physics/Collision/CollisionCollectorImpl.h>
#include <Jolt/Physics/Collision/GroupFilterTable.h>
#include <Jolt/Physics/Collision/NarrowPhaseQuery.h>
#include <Jolt/Physics/Collision/ObjectLayerPairFilterTable.h>
#include <Jolt/Physics/Collision/Shape/BoxShape.h>
#include <Jolt/Physics/Collision/Shape/CapsuleShape.h>
#include <Jolt/Physics/Collision/Shape/ConvexHullShape.h>
#include <Jolt/Physics/Collision/Shape/MeshShape.h>
#include <Jolt/Physics/Collision/Shape/PlaneShape.h>
#include <Jolt/Physics/Collision/Shape/SphereShape.h>
#include <Jolt/Physics/Constraints/PointConstraint.h>
#include <Jolt/Physics/PhysicsSettings.h>
#include <Jolt/Physics/PhysicsSystem.h>
#include <Jolt/RegisterTypes.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#ifndef JOLT_NATIVE_VERSION   // the version the build names (bench/peers/jolt_build.py), else Jolt's own
#define JOLT_STR2(x) #x
#define JOLT_STR(x) JOLT_STR2(x)
#define JOLT_NATIVE_VERSION JOLT_STR(JPH_VERSION_MAJOR) "." JOLT_STR(JPH_VERSION_MINOR) "." JOLT_STR(JPH_VERSION_PATCH)
#endif

// ---------------------------------------------------------------------------------------------------------------
// JSON: a reader for the requests and a writer for the answers, enough for the protocol (objects, arrays,
// strings, numbers, true, false, null; NaN and Infinity as Python's json module writes them).

namespace json {

struct Value {
    enum Kind { Null, Bool, Number, String, Array, Object } kind = Null;
    double number = 0.0;                                 // Number; Bool as 0 or 1
    std::string text;                                    // String
    std::vector<double> numbers;                         // Array: its elements while they are all numbers
    std::vector<Value> items;                            // Array: its elements once one is not a number
    std::vector<std::pair<std::string, Value>> members;  // Object, in their order

    const Value *find(const std::string &key) const {
        for (const auto &m : members) {
            if (m.first == key) {
                return &m.second;
            }
        }
        return nullptr;
    }
    const Value &operator[](const std::string &key) const {
        const Value *v = kind == Object ? find(key) : nullptr;
        if (v == nullptr) {
            throw std::runtime_error("missing \"" + key + "\"");
        }
        return *v;
    }
    double num() const {
        if (kind != Number) {
            throw std::runtime_error("expected a number");
        }
        return number;
    }
    const std::vector<double> &nums() const {     // an array of numbers
        if (kind != Array || !items.empty()) {
            throw std::runtime_error("expected an array of numbers");
        }
        return numbers;
    }
    const std::vector<Value> &list() const {      // an array of anything but numbers
        if (kind != Array || !numbers.empty()) {
            throw std::runtime_error("expected an array of objects");
        }
        return items;
    }
    const std::string &str() const {
        if (kind != String) {
            throw std::runtime_error("expected a string");
        }
        return text;
    }
};

class Reader {
public:
    explicit Reader(const std::string &text) : s_(text) {}

    Value document() {
        Value v = value();
        skip();
        if (i_ != s_.size()) {
            fail("text after the value");
        }
        return v;
    }

private:
    const std::string &s_;
    size_t i_ = 0;

    [[noreturn]] void fail(const std::string &what) const {
        throw std::runtime_error("bad JSON at character " + std::to_string(i_) + ": " + what);
    }
    void skip() {
        while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) {
            ++i_;
        }
    }
    bool eat(char c) {
        skip();
        if (i_ < s_.size() && s_[i_] == c) {
            ++i_;
            return true;
        }
        return false;
    }
    void expect(char c) {
        if (!eat(c)) {
            fail(std::string("expected '") + c + "'");
        }
    }
    bool word(const char *w) {
        size_t n = std::strlen(w);
        if (s_.compare(i_, n, w) != 0) {
            return false;
        }
        i_ += n;
        return true;
    }

    Value value() {
        skip();
        if (i_ >= s_.size()) {
            fail("unexpected end");
        }
        Value v;
        char c = s_[i_];
        if (c == '{') {
            ++i_;
            v.kind = Value::Object;
            if (!eat('}')) {
                do {
                    skip();
                    std::string key = string();
                    expect(':');
                    v.members.emplace_back(std::move(key), value());
                } while (eat(','));
                expect('}');
            }
        } else if (c == '[') {
            ++i_;
            v.kind = Value::Array;
            if (!eat(']')) {
                do {
                    Value e = value();
                    if (e.kind == Value::Number && v.items.empty()) {
                        v.numbers.push_back(e.number);
                        continue;
                    }
                    for (double x : v.numbers) {        // not all numbers: every element a Value
                        v.items.emplace_back().kind = Value::Number;
                        v.items.back().number = x;
                    }
                    v.numbers.clear();
                    v.items.push_back(std::move(e));
                } while (eat(','));
                expect(']');
            }
        } else if (c == '"') {
            v.kind = Value::String;
            v.text = string();
        } else if (word("true") || word("false")) {
            v.kind = Value::Bool;
            v.number = c == 't' ? 1.0 : 0.0;
        } else if (word("null")) {
            v.kind = Value::Null;
        } else {                                        // a number, NaN, Infinity or -Infinity
            const char *start = s_.c_str() + i_;
            char *end = nullptr;
            v.number = std::strtod(start, &end);
            if (end == start) {
                fail("expected a value");
            }
            v.kind = Value::Number;
            i_ += static_cast<size_t>(end - start);
        }
        return v;
    }

    std::string string() {
        if (i_ >= s_.size() || s_[i_] != '"') {
            fail("expected a string");
        }
        ++i_;
        std::string out;
        while (true) {
            if (i_ >= s_.size()) {
                fail("unterminated string");
            }
            char c = s_[i_++];
            if (c == '"') {
                return out;
            }
            if (c != '\\') {
                out += c;
                continue;
            }
            if (i_ >= s_.size()) {
                fail("unterminated string");
            }
            char e = s_[i_++];
            const char *plain = std::strchr("\"\\/bfnrt", e);
            if (e != '\0' && plain != nullptr) {
                out += "\"\\/\b\f\n\r\t"[plain - "\"\\/bfnrt"];
            } else if (e == 'u' && i_ + 4 <= s_.size()) {
                unsigned code = static_cast<unsigned>(std::stoul(s_.substr(i_, 4), nullptr, 16));
                i_ += 4;
                if (code < 0x80) {                      // UTF-8 (a surrogate pair's halves each on their own)
                    out += static_cast<char>(code);
                } else if (code < 0x800) {
                    out += static_cast<char>(0xC0 | (code >> 6));
                    out += static_cast<char>(0x80 | (code & 0x3F));
                } else {
                    out += static_cast<char>(0xE0 | (code >> 12));
                    out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
                    out += static_cast<char>(0x80 | (code & 0x3F));
                }
            } else {
                fail("bad escape");
            }
        }
    }
};

Value parse(const std::string &text) {
    return Reader(text).document();
}

// Writing: numbers with 17 significant digits (as many as a double needs), not-a-number and the infinities as
// null (as JavaScript's JSON.stringify writes them).
void number(std::string &out, double x) {
    if (!std::isfinite(x)) {
        out += "null";
        return;
    }
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.17g", x);
    out += buffer;
}

void string(std::string &out, const std::string &s) {
    out += '"';
    for (char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char buffer[8];
            std::snprintf(buffer, sizeof buffer, "\\u%04x", static_cast<unsigned>(c));
            out += buffer;
        } else {
            out += c;
        }
    }
    out += '"';
}

void numbers(std::string &out, const std::vector<double> &xs) {
    out += '[';
    for (size_t k = 0; k < xs.size(); ++k) {
        if (k > 0) {
            out += ',';
        }
        number(out, xs[k]);
    }
    out += ']';
}

void write(std::string &out, const Value &v) {
    switch (v.kind) {
    case Value::Null: out += "null"; break;
    case Value::Bool: out += v.number != 0.0 ? "true" : "false"; break;
    case Value::Number: number(out, v.number); break;
    case Value::String: string(out, v.text); break;
    case Value::Array:
        if (v.items.empty()) {
            numbers(out, v.numbers);
            break;
        }
        out += '[';
        for (size_t k = 0; k < v.items.size(); ++k) {
            out += k > 0 ? "," : "";
            write(out, v.items[k]);
        }
        out += ']';
        break;
    case Value::Object:
        out += '{';
        for (size_t k = 0; k < v.members.size(); ++k) {
            out += k > 0 ? "," : "";
            string(out, v.members[k].first);
            out += ':';
            write(out, v.members[k].second);
        }
        out += '}';
        break;
    }
}

}  // namespace json

// ---------------------------------------------------------------------------------------------------------------
// The Jolt world.

namespace {

using namespace JPH;

// object layers, each in the broad-phase layer of the same number
constexpr ObjectLayer STATIC = 0;
constexpr ObjectLayer MOVING = 1;
// linear speed cap (m/s): none that a scene reaches
constexpr float NO_SPEED_CAP = 1e10f;
// Jolt's default convex radius (m): the rounding of its boxes' edges, less for thinner boxes
constexpr float CONVEX_RADIUS = 0.05f;
// jolt-physics' JoltInterface sizes (its JoltSettings' defaults)
constexpr uint MAX_BODIES = 10240;
constexpr uint MAX_BODY_PAIRS = 65536;
constexpr uint MAX_CONTACT_CONSTRAINTS = 10240;
constexpr uint TEMP_ALLOCATOR_BYTES = 10 * 1024 * 1024;

void trace(const char *format, ...) {
    va_list args;
    va_start(args, format);
    std::vfprintf(stderr, format, args);
    va_end(args);
    std::fputc('\n', stderr);
}

Vec3 vec3(const json::Value &v) {
    const std::vector<double> &x = v.nums();
    if (x.size() != 3) {
        throw std::runtime_error("expected 3 numbers");
    }
    return Vec3(float(x[0]), float(x[1]), float(x[2]));
}

ShapeRefC created(const ShapeSettings &settings) {
    ShapeSettings::ShapeResult result = settings.Create();
    if (result.HasError()) {
        throw std::runtime_error(std::string("Jolt refused the shape: ") + result.GetError().c_str());
    }
    return result.Get();
}

ShapeRefC shape(const json::Value &s) {
    const std::string &kind = s["kind"].str();
    if (kind == "sphere") {
        return new SphereShape(float(s["radius"].num()));
    }
    if (kind == "box") {
        Vec3 h = vec3(s["half_extents"]);
        return new BoxShape(h, std::min(CONVEX_RADIUS, h.ReduceMin()));
    }
    if (kind == "capsule") {
        return new CapsuleShape(float(s["half_height"].num()), float(s["radius"].num()));
    }
    if (kind == "plane") {
        // Jolt's plane is n . x + c = 0 with the solid below; Marbellous' is n . x = offset
        return new PlaneShape(Plane(vec3(s["normal"]), -float(s["offset"].num())));
    }
    if (kind == "hull") {
        const std::vector<double> &p = s["points"].nums();
        Array<Vec3> points;
        for (size_t k = 0; k + 2 < p.size(); k += 3) {
            points.push_back(Vec3(float(p[k]), float(p[k + 1]), float(p[k + 2])));
        }
        return created(ConvexHullShapeSettings(points));
    }
    if (kind == "mesh") {
        const std::vector<double> &v = s["vertices"].nums();
        const std::vector<double> &t = s["triangles"].nums();
        VertexList vertices;
        vertices.reserve(v.size() / 3);
        for (size_t k = 0; k + 2 < v.size(); k += 3) {
            vertices.push_back(Float3(float(v[k]), float(v[k + 1]), float(v[k + 2])));
        }
        IndexedTriangleList triangles;
        triangles.reserve(t.size() / 3);
        for (size_t k = 0; k + 2 < t.size(); k += 3) {
            triangles.push_back(IndexedTriangle(uint32(t[k]), uint32(t[k + 1]), uint32(t[k + 2]), 0));
        }
        return created(MeshShapeSettings(std::move(vertices), std::move(triangles)));
    }
    throw std::runtime_error("no Jolt shape for " + kind);
}

// A ball joint of the build request: bodies a and b (b < 0: the world) held together at a world point (m).
struct BallJoint {
    size_t a;
    long b;
    RVec3 anchor;
};

std::vector<BallJoint> ball_joints(const json::Value &spec, size_t bodies) {
    std::vector<BallJoint> out;
    const json::Value *joints = spec.find("joints");     // (a build without "joints" has none)
    if (joints == nullptr) {
        return out;
    }
    for (const json::Value &j : joints->list()) {
        const std::string &kind = j["kind"].str();
        if (kind != "ball") {
            throw std::runtime_error("no Jolt joint for " + kind);
        }
        double a = j["body_a"].num(), b = j["body_b"].num();
        if (!(a >= 0.0 && a < double(bodies) && b >= -1.0 && b < double(bodies) && a != b)) {
            throw std::runtime_error("no bodies " + std::to_string(long(a)) + " and " + std::to_string(long(b)) +
                                     " to join");
        }
        out.push_back({size_t(a), long(b), RVec3(vec3(j["anchor"]))});
    }
    return out;
}

// The collision group of each body: each set of bodies that joints join (a component of the graph of joints
// between bodies) is a group with a table of its own, each of its bodies a sub-group, and the table keeps the two
// bodies of each joint from colliding; bodies no joint joins to another keep Jolt's default, no group.
std::vector<CollisionGroup> collision_groups(const std::vector<BallJoint> &joints, size_t bodies) {
    std::vector<size_t> root(bodies);
    std::iota(root.begin(), root.end(), size_t(0));
    auto find = [&root](size_t k) {
        while (root[k] != k) {
            k = root[k] = root[root[k]];
        }
        return k;
    };
    std::vector<bool> joined(bodies, false);
    for (const BallJoint &j : joints) {
        if (j.b >= 0) {
            root[find(j.a)] = find(size_t(j.b));
            joined[j.a] = joined[size_t(j.b)] = true;
        }
    }
    std::vector<CollisionGroup::SubGroupID> sub(bodies, 0);
    std::vector<uint> members(bodies, 0);
    for (size_t k = 0; k < bodies; ++k) {
        if (joined[k]) {
            sub[k] = members[find(k)]++;
        }
    }
    std::vector<Ref<GroupFilterTable>> tables(bodies);
    for (size_t k = 0; k < bodies; ++k) {
        if (joined[k] && tables[find(k)] == nullptr) {
            tables[find(k)] = new GroupFilterTable(members[find(k)]);
        }
    }
    for (const BallJoint &j : joints) {
        if (j.b >= 0) {
            tables[find(j.a)]->DisableCollision(sub[j.a], sub[size_t(j.b)]);
        }
    }
    std::vector<CollisionGroup> groups(bodies);
    for (size_t k = 0; k < bodies; ++k) {
        if (joined[k]) {
            groups[k] = CollisionGroup(tables[find(k)], CollisionGroup::GroupID(find(k)), sub[k]);
        }
    }
    return groups;
}

// One scene: its layer tables, the physics system, the bodies and the constraints, all gone with it.
struct Scene {
    ObjectLayerPairFilterTable pairs{2};
    BroadPhaseLayerInterfaceTable layers{2, 2};
    std::unique_ptr<ObjectVsBroadPhaseLayerFilterTable> layer_filter;
    PhysicsSystem system;               // declared after the tables it uses: destroyed before them
    std::vector<BodyID> bodies;
    std::vector<const Body *> dynamic;  // in build order
    std::vector<Constraint *> constraints;
    float dt = 0.0f;

    ~Scene() {
        if (!constraints.empty()) {     // before their bodies
            system.RemoveConstraints(constraints.data(), int(constraints.size()));
        }
        BodyInterface &bi = system.GetBodyInterfaceNoLock();
        if (!bodies.empty()) {
            bi.RemoveBodies(bodies.data(), int(bodies.size()));
            bi.DestroyBodies(bodies.data(), int(bodies.size()));
        }
    }
};

std::unique_ptr<Scene> build(const json::Value &spec) {
    auto scene = std::make_unique<Scene>();
    scene->pairs.EnableCollision(STATIC, MOVING);
    scene->pairs.EnableCollision(MOVING, MOVING);
    scene->layers.MapObjectToBroadPhaseLayer(STATIC, BroadPhaseLayer(STATIC));
    scene->layers.MapObjectToBroadPhaseLayer(MOVING, BroadPhaseLayer(MOVING));
    scene->layer_filter = std::make_unique<ObjectVsBroadPhaseLayerFilterTable>(scene->layers, 2, scene->pairs, 2);
    const std::vector<json::Value> &specs = spec["bodies"].list();
    scene->system.Init(std::max<uint>(MAX_BODIES, uint(specs.size())), 0, MAX_BODY_PAIRS, MAX_CONTACT_CONSTRAINTS,
                       scene->layers, *scene->layer_filter, scene->pairs);
    scene->system.SetGravity(vec3(spec["gravity"]));
    scene->dt = float(spec["dt"].num());
    std::vector<ShapeRefC> shapes;
    for (const json::Value &s : spec["shapes"].list()) {
        shapes.push_back(shape(s));
    }
    std::vector<BallJoint> joints = ball_joints(spec, specs.size());
    std::vector<CollisionGroup> groups = collision_groups(joints, specs.size());
    std::vector<Body *> created;
    BodyInterface &bi = scene->system.GetBodyInterface();
    // (a build without "sleeping" lets bodies sleep, Jolt's default)
    const json::Value *sleeping_spec = spec.find("sleeping");
    bool sleeping = sleeping_spec == nullptr || sleeping_spec->number != 0.0;
    for (const json::Value &b : specs) {
        size_t index = size_t(b["shape"].num());
        if (index >= shapes.size()) {
            throw std::runtime_error("no shape " + std::to_string(index));
        }
        bool is_static = b["static"].kind == json::Value::Bool && b["static"].number != 0.0;
        const std::vector<double> &q = b["orientation"].nums();   // w, x, y, z
        if (q.size() != 4) {
            throw std::runtime_error("expected an orientation of 4 numbers");
        }
        BodyCreationSettings settings(shapes[index], RVec3(vec3(b["position"])),
                                      Quat(float(q[1]), float(q[2]), float(q[3]), float(q[0])),
                                      is_static ? EMotionType::Static : EMotionType::Dynamic,
                                      is_static ? STATIC : MOVING);
        settings.mFriction = float(b["friction"].num());
        settings.mRestitution = float(b["restitution"].num());
        settings.mCollisionGroup = groups[created.size()];
        if (!is_static) {
            settings.mLinearVelocity = vec3(b["velocity"]);
            settings.mAngularVelocity = vec3(b["angular_velocity"]);
            settings.mLinearDamping = 0.0f;
            settings.mAngularDamping = 0.0f;
            settings.mMaxLinearVelocity = NO_SPEED_CAP;
            settings.mOverrideMassProperties = EOverrideMassProperties::CalculateInertia;
            settings.mMassPropertiesOverride.mMass = float(b["mass"].num());
            settings.mAllowSleeping = sleeping;
        }
        Body *body = bi.CreateBody(settings);
        if (body == nullptr) {
            throw std::runtime_error("no room for body " + std::to_string(scene->bodies.size()) + ": Jolt's body limit");
        }
        scene->bodies.push_back(body->GetID());
        bi.AddBody(body->GetID(), is_static ? EActivation::DontActivate : EActivation::Activate);
        created.push_back(body);
        if (!is_static) {
            scene->dynamic.push_back(body);
        }
    }
    // each ball joint a point constraint: a point of each body (or of the world) kept on the other's, both where
    // the anchor is now
    for (const BallJoint &j : joints) {
        PointConstraintSettings point;
        point.mSpace = EConstraintSpace::WorldSpace;
        point.mPoint1 = point.mPoint2 = j.anchor;
        Constraint *c = point.Create(*created[j.a], j.b < 0 ? Body::sFixedToWorld : *created[size_t(j.b)]);
        scene->system.AddConstraint(c);
        scene->constraints.push_back(c);
    }
    scene->system.OptimizeBroadPhase();
    return scene;
}

std::string update_error(EPhysicsUpdateError e) {
    std::string full;
    auto add = [&](EPhysicsUpdateError flag, const std::string &name) {
        if ((e & flag) != EPhysicsUpdateError::None) {
            full += (full.empty() ? "" : ", ") + std::string(name);
        }
    };
    add(EPhysicsUpdateError::ManifoldCacheFull, "manifold cache");
    add(EPhysicsUpdateError::BodyPairCacheFull, "body pair cache (" + std::to_string(MAX_BODY_PAIRS) + " pairs)");
    add(EPhysicsUpdateError::ContactConstraintsFull,
        "contact constraints (" + std::to_string(MAX_CONTACT_CONSTRAINTS) + ")");
    return "Jolt's " + full + " full: it drops the contacts past them and bodies sink into each other";
}

class Driver {
public:
    Driver(TempAllocator &temp, JobSystem &jobs) : temp_(temp), jobs_(jobs) {}

    // A second of a small scene with every kind of shape, contact and joint (driver.mjs' warm-up), stepped before
    // any request and then replaced by the scene built, so that the first calls of Jolt's code paths (its first
    // allocations, the pages its tables first touch) are not timed.
    void warm_up() {
        scene_ = build(json::parse(R"({"dt": 0.016666666666666666, "gravity": [0, -9.81, 0], "shapes": [
            {"kind": "plane", "normal": [0, 1, 0], "offset": 0},
            {"kind": "mesh", "vertices": [8, 0, -2, 12, 0, -2, 12, 0, 2, 8, 0, 2], "triangles": [0, 2, 1, 0, 3, 2]},
            {"kind": "box", "half_extents": [0.5, 0.5, 0.5]}, {"kind": "sphere", "radius": 0.5},
            {"kind": "capsule", "radius": 0.3, "half_height": 0.4},
            {"kind": "hull", "points": [-0.5, -0.5, -0.5, -0.5, -0.5, 0.5, -0.5, 0.5, -0.5, -0.5, 0.5, 0.5,
                                        0.5, -0.5, -0.5, 0.5, -0.5, 0.5, 0.5, 0.5, -0.5, 0.5, 0.5, 0.5]}],
            "bodies": [)" + warm_up_body(0, "0, 0, 0", true) + "," + warm_up_body(1, "0, 0.5, 0", true) + "," +
            warm_up_body(2, "0, 0.5, 0") + "," + warm_up_body(2, "0.2, 1.6, 0") + "," +
            warm_up_body(3, "-0.1, 2.8, 0.1") + "," + warm_up_body(3, "2, 0.6, 0") + "," +
            warm_up_body(4, "3, 1, 0") + "," + warm_up_body(5, "4.5, 1, 0") + "," + warm_up_body(3, "10, 1, 0") +
            "," + warm_up_body(2, "10, 3, 0.5") + R"(], "joints": [
            {"kind": "ball", "body_a": 9, "body_b": -1, "anchor": [10, 3.5, 0.5]},
            {"kind": "ball", "body_a": 8, "body_b": 9, "anchor": [10, 2, 0.25]}]})"));
        for (int k = 0; k < 60; ++k) {
            scene_->system.Update(scene_->dt, 1, &temp_, &jobs_);
        }
    }

    // The answer to one request (without its newline); throws std::runtime_error when it fails.
    std::string answer(const json::Value &request) {
        const std::string &op = request["op"].str();
        std::string out;
        if (op == "build") {
            scene_.reset();     // the scene built before, its bodies and layer tables with it
            scene_ = build(request);
            out = "{\"version\":";
            json::string(out, JOLT_NATIVE_VERSION);
            return out + "}";
        }
        if (op == "echo") {
            out = "{\"value\":";
            json::write(out, request["value"]);
            return out + "}";
        }
        if (op == "step") {
            const json::Value *budget = request.find("budget");
            bool limited = budget != nullptr && budget->kind != json::Value::Null;
            out = "{\"seconds\":";
            json::numbers(out, steps(long(request["n"].num()), limited ? budget->num() : 0.0, limited));
            return out + "}";
        }
        if (op == "positions") {
            std::vector<double> p;
            p.reserve(3 * scene_->dynamic.size());
            for (const Body *body : scene_->dynamic) {
                RVec3 x = body->GetPosition();
                p.insert(p.end(), {double(x.GetX()), double(x.GetY()), double(x.GetZ())});
            }
            out = "{\"positions\":";
            json::numbers(out, p);
            return out + "}";
        }
        if (op == "orientations") {
            std::vector<double> q;
            q.reserve(4 * scene_->dynamic.size());
            for (const Body *body : scene_->dynamic) {
                Quat r = body->GetRotation();
                q.insert(q.end(), {double(r.GetW()), double(r.GetX()), double(r.GetY()), double(r.GetZ())});
            }
            out = "{\"orientations\":";
            json::numbers(out, q);
            return out + "}";
        }
        if (op == "penetration") {
            out = "{\"depth\":";
            json::number(out, penetration());
            return out + "}";
        }
        throw std::runtime_error("unknown op " + op);
    }

private:
    TempAllocator &temp_;
    JobSystem &jobs_;
    std::unique_ptr<Scene> scene_;

    static std::string warm_up_body(int shape, const char *position, bool is_static = false) {
        return "{\"shape\": " + std::to_string(shape) + ", \"static\": " + (is_static ? "true" : "false") +
               ", \"position\": [" + position + "], \"orientation\": [1, 0, 0, 0], \"velocity\": [0, 0, 0], "
               "\"angular_velocity\": [0, 0, 0], \"mass\": " + (is_static ? "0" : "1") +
               ", \"friction\": 0.5, \"restitution\": 0}";
    }

    std::vector<double> steps(long n, double budget, bool limited) {
        std::vector<double> seconds;
        double spent = 0.0;
        for (long k = 0; k < n; ++k) {
            auto start = std::chrono::steady_clock::now();
            EPhysicsUpdateError error = scene_->system.Update(scene_->dt, 1, &temp_, &jobs_);
            double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            if (error != EPhysicsUpdateError::None) {
                throw std::runtime_error(update_error(error));
            }
            seconds.push_back(s);
            spent += s;
            if (limited && spent > budget) {
                break;
            }
        }
        return seconds;
    }

    // Jolt keeps its contact manifolds to itself: each dynamic body's shape is collided against the world by
    // Jolt's own narrow phase instead, at the current poses, without a separation margin (as jolt.mjs does).
    double penetration() const {
        const PhysicsSystem &system = scene_->system;
        CollideShapeSettings settings;
        settings.mMaxSeparationDistance = 0.0f;
        DefaultBroadPhaseLayerFilter layers = system.GetDefaultBroadPhaseLayerFilter(MOVING);
        DefaultObjectLayerFilter objects = system.GetDefaultLayerFilter(MOVING);
        float deepest = 0.0f;
        for (const Body *body : scene_->dynamic) {
            AllHitCollisionCollector<CollideShapeCollector> hits;
            IgnoreSingleBodyFilter others(body->GetID());
            system.GetNarrowPhaseQuery().CollideShape(body->GetShape(), Vec3::sOne(), body->GetCenterOfMassTransform(),
                                                      settings, RVec3::sZero(), hits, layers, objects, others);
            for (const CollideShapeResult &hit : hits.mHits) {
                deepest = std::max(deepest, hit.mPenetrationDepth);
            }
        }
        return deepest;
    }
};

void say(const std::string &line) {
    std::fwrite(line.data(), 1, line.size(), stdout);
    std::fputc('\n', stdout);
    std::fflush(stdout);
}

}  // namespace

int main(int argc, char **argv) {
    int threads = 1;
    for (int k = 1; k < argc; ++k) {
        if (std::strcmp(argv[k], "--threads") == 0 && k + 1 < argc) {
            threads = std::atoi(argv[++k]);
        } else {
            threads = 0;
        }
    }
    if (threads < 1) {
        std::fprintf(stderr, "usage: %s [--threads N]  (N >= 1)\n", argv[0]);
        return 2;
    }
    RegisterDefaultAllocator();
    Trace = trace;
    Factory::sInstance = new Factory();
    RegisterTypes();
    int status = 0;
    {
        TempAllocatorImpl temp(TEMP_ALLOCATOR_BYTES);
        std::unique_ptr<JobSystem> jobs;
        if (threads == 1) {
            jobs = std::make_unique<JobSystemSingleThreaded>(cMaxPhysicsJobs);
        } else {
            jobs = std::make_unique<JobSystemThreadPool>(cMaxPhysicsJobs, cMaxPhysicsBarriers, threads - 1);
        }
        Driver driver(temp, *jobs);
        driver.warm_up();
        std::string line;
        while (std::getline(std::cin, line)) {
            if (line.find_first_not_of(" \t\r") == std::string::npos) {
                continue;
            }
            try {
                json::Value request = json::parse(line);
                if (request["op"].str() == "close") {
                    break;
                }
                say(driver.answer(request));
            } catch (const std::exception &e) {
                std::string out = "{\"error\":";
                json::string(out, e.what());
                say(out + "}");
                status = 1;
                break;
            }
        }
    }
    UnregisterTypes();
    delete Factory::sInstance;
    Factory::sInstance = nullptr;
    return status;
}
