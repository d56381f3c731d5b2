// Jolt Physics (npm jolt-physics, its single-threaded WebAssembly build) as a backend of driver.mjs.
//
// Two object layers, static and moving, each in a broad-phase layer of its own; moving bodies collide with
// both, static ones only with moving ones.  Jolt's defaults otherwise (10 velocity and 2 position iterations,
// sleeping unless the build says not, body pairs and contact constraints as jolt-physics sizes them), except: room for every body of
// the scene when it has more than Jolt's default 10,240; no linear or angular damping (Jolt's default is
// 0.05); no cap on linear speed (Jolt's default is 500 m/s); the mass given, the inertia Jolt computes for it
// from the shape.  Jolt combines friction by geometric mean and restitution by maximum, as Marbellous does,
// so each body keeps its own coefficients.  A ball joint is Jolt's point constraint, its two points on the
// anchor; the two bodies do not collide with each other, as in Marbellous: each set of bodies that joints join
// is a collision group in which a joined pair does not collide (the same in jolt_native/driver.cpp).
import { pathToFileURL } from "node:url";

// object layers, each in the broad-phase layer of the same number
const STATIC = 0;
const MOVING = 1;
// linear speed cap (m/s): none that a scene reaches
const NO_SPEED_CAP = 1e10;
// Jolt's default convex radius (m): the rounding of its boxes' edges, less for thinner boxes
const CONVEX_RADIUS = 0.05;

export async function load(require) {
    const packageFile = require.resolve("jolt-physics/package.json");
    const init = (await import(pathToFileURL(require.resolve("jolt-physics")).href)).default;
    return new JoltWorld(await init(), require(packageFile).version);
}

class JoltWorld {
    constructor(Jolt, version) {
        this.J = Jolt;
        this.version = version;
    }

    build(spec) {
        const J = this.J;
        if (this.jolt) {
            J.destroy(this.jolt);   // the scene built before, its bodies and layer tables with it
        }
        const settings = new J.JoltSettings();
        settings.mMaxBodies = Math.max(settings.mMaxBodies, spec.bodies.length);
        const pairs = new J.ObjectLayerPairFilterTable(2);
        pairs.EnableCollision(STATIC, MOVING);
        pairs.EnableCollision(MOVING, MOVING);
        const layers = new J.BroadPhaseLayerInterfaceTable(2, 2);
        layers.MapObjectToBroadPhaseLayer(STATIC, new J.BroadPhaseLayer(STATIC));
        layers.MapObjectToBroadPhaseLayer(MOVING, new J.BroadPhaseLayer(MOVING));
        settings.mObjectLayerPairFilter = pairs;
        settings.mBroadPhaseLayerInterface = layers;
        settings.mObjectVsBroadPhaseLayerFilter = new J.ObjectVsBroadPhaseLayerFilterTable(layers, 2, pairs, 2);
        this.maxContacts = settings.mMaxContactConstraints;
        this.jolt = new J.JoltInterface(settings);
        J.destroy(settings);
        this.system = this.jolt.GetPhysicsSystem();
        this.system.SetGravity(new J.Vec3(...spec.gravity));
        this.dt = spec.dt;
        const shapes = spec.shapes.map((s) => this.shape(s));
        const joints = spec.joints ?? [];
        const groups = this.collisionGroups(joints, spec.bodies.length);
        const bodies = this.system.GetBodyInterface();
        const created = [];
        this.dynamic = [];
        const [position, rotation, velocity] = [new J.RVec3(), new J.Quat(), new J.Vec3()];
        for (const b of spec.bodies) {
            const [w, x, y, z] = b.orientation;
            position.Set(...b.position);
            rotation.Set(x, y, z, w);
            const motion = b.static ? J.EMotionType_Static : J.EMotionType_Dynamic;
            const settings = new J.BodyCreationSettings(shapes[b.shape], position, rotation, motion,
                b.static ? STATIC : MOVING);
            settings.mFriction = b.friction;
            settings.mRestitution = b.restitution;
            if (groups[created.length] !== undefined) {
                settings.mCollisionGroup = groups[created.length];
            }
            if (!b.static) {
                velocity.Set(...b.velocity);
                settings.mLinearVelocity = velocity;
                velocity.Set(...b.angular_velocity);
                settings.mAngularVelocity = velocity;
                settings.mLinearDamping = 0.0;
                settings.mAngularDamping = 0.0;
                settings.mMaxLinearVelocity = NO_SPEED_CAP;
                settings.mOverrideMassProperties = J.EOverrideMassProperties_CalculateInertia;
                const mass = new J.MassProperties();
                mass.mMass = b.mass;
                settings.mMassPropertiesOverride = mass;
                J.destroy(mass);
                settings.mAllowSleeping = spec.sleeping !== false;
            }
            const body = bodies.CreateBody(settings);
            J.destroy(settings);
            if (J.getPointer(body) === 0) {
                throw new Error(`no room for body ${this.dynamic.length}: Jolt's body limit`);
            }
            bodies.AddBody(body.GetID(), b.static ? J.EActivation_DontActivate : J.EActivation_Activate);
            created.push(body);
            if (!b.static) {
                this.dynamic.push(body);
            }
        }
        for (const group of groups) {
            if (group !== undefined) {
                J.destroy(group);   // copied into the bodies, which hold their tables
            }
        }
        // each ball joint a point constraint: a point of each body (or of the world) kept on the other's, both
        // where the anchor is now
        const point = new J.PointConstraintSettings();
        point.mSpace = J.EConstraintSpace_WorldSpace;
        for (const j of joints) {
            if (j.kind !== "ball") {
                throw new Error(`no Jolt joint for ${j.kind}`);
            }
            position.Set(...j.anchor);
            point.mPoint1 = position;
            point.mPoint2 = position;
            const other = j.body_b < 0 ? this.jolt.sGetFixedToWorldBody() : created[j.body_b];
            this.system.AddConstraint(point.Create(created[j.body_a], other));
        }
        J.destroy(point);
        for (const o of [position, rotation, velocity]) {
            J.destroy(o);
        }
        this.system.OptimizeBroadPhase();
        return this.version;
    }

    // The collision group of each body (an array, undefined for a body no joint joins to another): each set of
    // bodies that joints join (a component of the graph of joints between bodies) is a group with a table of its
    // own, each of its bodies a sub-group, and the table keeps the two bodies of each joint from colliding.
    collisionGroups(joints, count) {
        const J = this.J;
        const root = Array.from({ length: count }, (_, k) => k);
        const find = (k) => {
            while (root[k] !== k) {
                k = root[k] = root[root[k]];
            }
            return k;
        };
        const between = joints.filter((j) => j.body_b >= 0);
        for (const j of between) {
            root[find(j.body_a)] = find(j.body_b);
        }
        const sub = new Map();          // body -> its sub-group
        const members = new Map();      // group (its root body) -> how many bodies it has so far
        for (const j of between) {
            for (const k of [j.body_a, j.body_b]) {
                if (!sub.has(k)) {
                    const r = find(k);
                    sub.set(k, members.get(r) ?? 0);
                    members.set(r, sub.get(k) + 1);
                }
            }
        }
        const tables = new Map([...members].map(([r, n]) => [r, new J.GroupFilterTable(n)]));
        for (const j of between) {
            tables.get(find(j.body_a)).DisableCollision(sub.get(j.body_a), sub.get(j.body_b));
        }
        const groups = new Array(count);
        for (const [k, s] of sub) {
            groups[k] = new J.CollisionGroup(tables.get(find(k)), find(k), s);
        }
        return groups;
    }

    shape(s) {
        const J = this.J;
        if (s.kind === "sphere") {
            return new J.SphereShape(s.radius);
        }
        if (s.kind === "box") {
            return new J.BoxShape(new J.Vec3(...s.half_extents), Math.min(CONVEX_RADIUS, ...s.half_extents));
        }
        if (s.kind === "capsule") {
            return new J.CapsuleShape(s.half_height, s.radius);
        }
        if (s.kind === "plane") {
            // Jolt's plane is n . x + c = 0 with the solid below; Marbellous' is n . x = offset
            return new J.PlaneShape(new J.Plane(new J.Vec3(...s.normal), -s.offset));
        }
        if (s.kind === "hull") {
            const settings = new J.ConvexHullShapeSettings();
            for (let k = 0; k < s.points.length; k += 3) {
                settings.mPoints.push_back(new J.Vec3(s.points[k], s.points[k + 1], s.points[k + 2]));
            }
            return this.created(settings);
        }
        if (s.kind === "mesh") {
            const vertices = new J.VertexList();
            vertices.reserve(s.vertices.length / 3);
            const v = new J.Float3(0, 0, 0);
            for (let k = 0; k < s.vertices.length; k += 3) {
                v.x = s.vertices[k];
                v.y = s.vertices[k + 1];
                v.z = s.vertices[k + 2];
                vertices.push_back(v);
            }
            const triangles = new J.IndexedTriangleList();
            triangles.reserve(s.triangles.length / 3);
            for (let k = 0; k < s.triangles.length; k += 3) {
                const t = new J.IndexedTriangle(s.triangles[k], s.triangles[k + 1], s.triangles[k + 2], 0);
                triangles.push_back(t);
                J.destroy(t);
            }
            return this.created(new J.MeshShapeSettings(vertices, triangles, new J.PhysicsMaterialList()));
        }
        throw new Error(`no Jolt shape for ${s.kind}`);
    }

    created(settings) {
        const result = settings.Create();
        if (result.HasError()) {
            throw new Error(`Jolt refused the shape: ${result.GetError().c_str()}`);
        }
        return result.Get();
    }

    step() {
        this.jolt.Step(this.dt, 1);
    }

    positions() {
        const out = [];
        for (const body of this.dynamic) {
            const p = body.GetPosition();
            out.push(p.GetX(), p.GetY(), p.GetZ());
        }
        return out;
    }

    // the dynamic bodies' orientations (unit quaternions), w, x, y, z each, in build order
    orientations() {
        const out = [];
        for (const body of this.dynamic) {
            const q = body.GetRotation();
            out.push(q.GetW(), q.GetX(), q.GetY(), q.GetZ());
        }
        return out;
    }

    penetration() {
        // Jolt keeps its contact manifolds to itself: each dynamic body's shape is collided against the world
        // by Jolt's own narrow phase instead, at the current poses, without a separation margin.  The pairs
        // found are counted too: past Jolt's contact constraints, it drops contacts without a word and bodies
        // fall through each other, so the run fails instead.
        const J = this.J;
        const query = this.system.GetNarrowPhaseQuery();
        const settings = new J.CollideShapeSettings();
        settings.mMaxSeparationDistance = 0.0;
        const scale = new J.Vec3(1.0, 1.0, 1.0);
        const origin = new J.RVec3(0.0, 0.0, 0.0);
        const layers = new J.DefaultBroadPhaseLayerFilter(this.jolt.GetObjectVsBroadPhaseLayerFilter(), MOVING);
        const objects = new J.DefaultObjectLayerFilter(this.jolt.GetObjectLayerPairFilter(), MOVING);
        const shapes = new J.ShapeFilter();
        let deepest = 0.0;
        let pairs = 0;
        const dynamic = new Set(this.dynamic.map((body) => body.GetID().GetIndex()));
        for (const body of this.dynamic) {
            const hits = new J.CollideShapeAllHitCollisionCollector();
            const others = new J.IgnoreSingleBodyFilter(body.GetID());
            query.CollideShape(body.GetShape(), scale, body.GetCenterOfMassTransform(), settings, origin, hits,
                layers, objects, others, shapes);
            const touching = new Set();
            for (let k = 0; k < hits.mHits.size(); k++) {
                const hit = hits.mHits.at(k);
                deepest = Math.max(deepest, hit.mPenetrationDepth);
                touching.add(hit.mBodyID2.GetIndex());
            }
            const own = body.GetID().GetIndex();
            for (const other of touching) {
                pairs += !dynamic.has(other) || other > own ? 1 : 0;    // each pair once
            }
            J.destroy(others);
            J.destroy(hits);
        }
        for (const o of [settings, scale, origin, layers, objects, shapes]) {
            J.destroy(o);
        }
        if (pairs > this.maxContacts) {
            throw new Error(`${pairs} pairs of bodies in contact, more than Jolt's ${this.maxContacts} contact `
                + "constraints: it drops the others and bodies sink into each other (jolt-physics 1.1.0 fixes its "
                + "temporary allocator at 10 MB, which holds 20,000 to 30,000 at most)");
        }
        return deepest;
    }
}
