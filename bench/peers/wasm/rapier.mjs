// Rapier (npm @dimforge/rapier3d-compat, WebAssembly) as a backend of driver.mjs.
//
// Each body is a rigid body (fixed or dynamic) with one collider.  Rapier's defaults otherwise (4 solver
// iterations, sleeping unless the build says not, no damping, no continuous collision, linear speed held to 400 m/s), except: the mass
// given, which sets the collider's density and so the inertia Rapier computes from the shape (its default
// density is 1 kg/m^3).
// Marbellous combines friction by geometric mean and restitution by maximum: each collider gets the square
// root of its friction coefficient with Rapier's "multiply" rule, whose product is that mean, and its
// restitution with the "max" rule.  A ball joint is Rapier's spherical impulse joint, its anchor in each body's
// frame (a joint to the world holds its body to a fixed body at the origin, without a collider), with the
// contacts between its two bodies off, as Marbellous has them.
export async function load(require) {
    const R = require("@dimforge/rapier3d-compat");
    await R.init();
    return new RapierWorld(R);
}

// The world point p (m) in the frame of a rigid body: its offset from the body's origin turned by the
// inverse of the body's rotation, v + w t + u x t with t = 2 u x v, where (w, u) is that inverse.
function localPoint(body, [px, py, pz]) {
    const t = body.translation();
    const q = body.rotation();
    const [w, ux, uy, uz] = [q.w, -q.x, -q.y, -q.z];
    const [vx, vy, vz] = [px - t.x, py - t.y, pz - t.z];
    const [tx, ty, tz] = [2 * (uy * vz - uz * vy), 2 * (uz * vx - ux * vz), 2 * (ux * vy - uy * vx)];
    return {
        x: vx + w * tx + uy * tz - uz * ty, y: vy + w * ty + uz * tx - ux * tz, z: vz + w * tz + ux * ty - uy * tx,
    };
}

class RapierWorld {
    constructor(R) {
        this.R = R;
    }

    build(spec) {
        const R = this.R;
        if (this.world) {
            this.world.free();     // the scene built before
        }
        const [gx, gy, gz] = spec.gravity;
        this.world = new R.World({ x: gx, y: gy, z: gz });
        this.world.timestep = spec.dt;
        this.dynamic = [];
        this.colliders = [];
        const created = [];
        for (const b of spec.bodies) {
            const [w, x, y, z] = b.orientation;
            const [px, py, pz] = b.position;
            const desc = (b.static ? R.RigidBodyDesc.fixed() : R.RigidBodyDesc.dynamic())
                .setTranslation(px, py, pz).setRotation({ w, x, y, z });
            if (!b.static) {
                const [vx, vy, vz] = b.velocity;
                const [ax, ay, az] = b.angular_velocity;
                desc.setLinvel(vx, vy, vz).setAngvel({ x: ax, y: ay, z: az }).setCanSleep(spec.sleeping !== false);
            }
            const body = this.world.createRigidBody(desc);
            const collider = this.collider(spec.shapes[b.shape])
                .setFriction(Math.sqrt(b.friction)).setFrictionCombineRule(R.CoefficientCombineRule.Multiply)
                .setRestitution(b.restitution).setRestitutionCombineRule(R.CoefficientCombineRule.Max);
            if (!b.static) {
                collider.setMass(b.mass);
                this.dynamic.push(body);
                this.colliders.push(this.world.createCollider(collider, body));
            } else {
                this.world.createCollider(collider, body);
            }
            created.push(body);
        }
        let ground = null;
        for (const j of spec.joints ?? []) {
            if (j.kind !== "ball") {
                throw new Error(`no Rapier joint for ${j.kind}`);
            }
            if (j.body_b < 0 && ground === null) {
                ground = this.world.createRigidBody(R.RigidBodyDesc.fixed());
            }
            const a = created[j.body_a];
            const b = j.body_b < 0 ? ground : created[j.body_b];
            const data = R.JointData.spherical(localPoint(a, j.anchor), localPoint(b, j.anchor));
            this.world.createImpulseJoint(data, a, b, true).setContactsEnabled(false);
        }
        return R.version();
    }

    collider(s) {
        const R = this.R;
        if (s.kind === "sphere") {
            return R.ColliderDesc.ball(s.radius);
        }
        if (s.kind === "box") {
            return R.ColliderDesc.cuboid(...s.half_extents);
        }
        if (s.kind === "capsule") {
            return R.ColliderDesc.capsule(s.half_height, s.radius);
        }
        if (s.kind === "plane") {
            // Rapier's half-space has its surface through the collider's origin: moved out to n . x = offset
            const [nx, ny, nz] = s.normal;
            return new R.ColliderDesc(new R.HalfSpace({ x: nx, y: ny, z: nz }))
                .setTranslation(nx * s.offset, ny * s.offset, nz * s.offset);
        }
        if (s.kind === "hull") {
            const desc = R.ColliderDesc.convexHull(new Float32Array(s.points));
            if (desc === null) {
                throw new Error("Rapier refused the convex hull's points");
            }
            return desc;
        }
        if (s.kind === "mesh") {
            return R.ColliderDesc.trimesh(new Float32Array(s.vertices), new Uint32Array(s.triangles));
        }
        throw new Error(`no Rapier shape for ${s.kind}`);
    }

    step() {
        this.world.step();
    }

    positions() {
        const out = [];
        for (const body of this.dynamic) {
            const p = body.translation();
            out.push(p.x, p.y, p.z);
        }
        return out;
    }

    // the dynamic bodies' orientations (unit quaternions), w, x, y, z each, in build order
    orientations() {
        const out = [];
        for (const body of this.dynamic) {
            const q = body.rotation();
            out.push(q.w, q.x, q.y, q.z);
        }
        return out;
    }

    penetration() {
        // Each dynamic collider against the colliders Rapier's narrow phase pairs it with, by Rapier's contact
        // query at the current poses: the manifolds it keeps are not refreshed for a body resting on a triangle
        // mesh (they keep the depth of the first impact).  The other collider goes first: Rapier 0.21 measures
        // a ball against a half-space wrongly the other way round.
        let deepest = 0.0;
        for (const collider of this.colliders) {
            this.world.contactPairsWith(collider, (other) => {
                const contact = other.contactCollider(collider, 0.0);
                if (contact !== null) {
                    deepest = Math.max(deepest, -contact.distance);
                }
            });
        }
        return deepest;
    }
}
