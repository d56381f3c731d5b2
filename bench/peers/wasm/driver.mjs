// One WebAssembly physics engine driven over line-delimited JSON: the benchmark's node side.
//
//     node driver.mjs ENGINE PREFIX      ENGINE: jolt or rapier; PREFIX: the npm prefix whose node_modules
//                                        holds the engine's package
//
// Each line read from stdin is one request, answered by one line on stdout:
//     {"op": "build", "dt": s, "gravity": [x, y, z], "sleeping": bool, "shapes": [...], "bodies": [...],
//      "joints": [...]}  ->  {"version": "x.y.z"}
//         "joints" (optional: none without it): {"kind": "ball", "body_a": i, "body_b": j, "anchor": [x, y, z]},
//         bodies i and j (indices into "bodies"; j = -1: the world) held together at a point, the anchor (m, world)
//         when built; the two bodies do not collide with each other.  Another kind fails the build.
//     {"op": "step", "n": k, "budget": s or null}  ->  {"seconds": [...]}  the time of each step (s), measured
//         here around the engine's step call alone; stops early once they add up to more than the budget
//     {"op": "positions"}  ->  {"positions": [x0, y0, z0, x1, ...]}  dynamic bodies in build order (m)
//     {"op": "orientations"}  ->  {"orientations": [w0, x0, y0, z0, w1, ...]}  the same bodies' (unit quaternions)
//     {"op": "penetration"}  ->  {"depth": d}  deepest overlap among the current contacts (m, 0 if none)
//     {"op": "close"}  ->  the process exits
// A request that fails is answered {"error": "message"} and the process exits with status 1 (a WebAssembly
// abort leaves the engine unusable).  Anything the engines print goes to stderr, never into the answers.
import { createRequire } from "node:module";
import path from "node:path";
import { performance } from "node:perf_hooks";
import { createInterface } from "node:readline";

console.log = console.error;
console.info = console.error;

const [engineName, prefix] = process.argv.slice(2);
const backends = { jolt: "./jolt.mjs", rapier: "./rapier.mjs" };
if (!(engineName in backends)) {
    process.stderr.write(`engine must be one of ${Object.keys(backends).join(", ")}, got ${engineName}\n`);
    process.exit(2);
}
const requireFromPrefix = createRequire(path.join(path.resolve(prefix), "package.json"));
const engine = await (await import(backends[engineName])).load(requireFromPrefix);
warmUp();

// A second of a small scene with every kind of shape, contact and joint, stepped once before any request (and then
// replaced by the scene built), so that the first calls of the engine's code paths (V8 compiling the
// engine's JavaScript, the engine's first allocations) are not timed, as the benchmark's warm-up compiles
// Marbellous' kernels before it times them.
function warmUp() {
    const body = (shape, position, isStatic = false) => ({
        shape, static: isStatic, position, orientation: [1, 0, 0, 0], velocity: [0, 0, 0],
        angular_velocity: [0, 0, 0], mass: isStatic ? 0 : 1, friction: 0.5, restitution: 0,
    });
    const signs = [-0.5, 0.5];
    const cube = signs.flatMap((x) => signs.flatMap((y) => signs.flatMap((z) => [x, y, z])));
    engine.build({
        dt: 1 / 60, gravity: [0, -9.81, 0],
        shapes: [
            { kind: "plane", normal: [0, 1, 0], offset: 0 },
            { kind: "mesh", vertices: [8, 0, -2, 12, 0, -2, 12, 0, 2, 8, 0, 2], triangles: [0, 2, 1, 0, 3, 2] },
            { kind: "box", half_extents: [0.5, 0.5, 0.5] },
            { kind: "sphere", radius: 0.5 },
            { kind: "capsule", radius: 0.3, half_height: 0.4 },
            { kind: "hull", points: cube },
        ],
        bodies: [
            body(0, [0, 0, 0], true), body(1, [0, 0.5, 0], true),
            body(2, [0, 0.5, 0]), body(2, [0.2, 1.6, 0]), body(3, [-0.1, 2.8, 0.1]), body(3, [2, 0.6, 0]),
            body(4, [3, 1, 0]), body(5, [4.5, 1, 0]), body(3, [10, 1, 0]), body(2, [10, 3, 0.5]),
        ],
        joints: [
            { kind: "ball", body_a: 9, body_b: -1, anchor: [10, 3.5, 0.5] },
            { kind: "ball", body_a: 8, body_b: 9, anchor: [10, 2, 0.25] },
        ],
    });
    for (let k = 0; k < 60; k++) {
        engine.step();
    }
}

// The request's arrays and the engine's building garbage, collected before any step is timed (with node's
// --expose-gc; else left to the collector).
function collectGarbage() {
    if (typeof globalThis.gc === "function") {
        globalThis.gc();
    }
}

function answer(reply) {
    process.stdout.write(JSON.stringify(reply) + "\n");
}

function steps(n, budget) {
    const seconds = [];
    let spent = 0.0;
    for (let k = 0; k < n; k++) {
        const start = performance.now();
        engine.step();
        const s = (performance.now() - start) * 1e-3;
        seconds.push(s);
        spent += s;
        if (budget !== null && spent > budget) {
            break;
        }
    }
    return { seconds };
}

const handlers = {
    build: (r) => {
        const version = engine.build(r);
        collectGarbage();
        return { version };
    },
    step: (r) => steps(r.n, r.budget ?? null),
    positions: () => ({ positions: engine.positions() }),
    orientations: () => ({ orientations: engine.orientations() }),
    penetration: () => ({ depth: engine.penetration() }),
    close: () => process.exit(0),
};

for await (const line of createInterface({ input: process.stdin, crlfDelay: Infinity })) {
    if (!line.trim()) {
        continue;
    }
    try {
        const request = JSON.parse(line);
        if (!(request.op in handlers)) {
            throw new Error(`unknown op ${request.op}`);
        }
        answer(handlers[request.op](request));
    } catch (e) {
        answer({ error: `${e && e.name ? e.name + ": " : ""}${e && e.message !== undefined ? e.message : e}` });
        process.exit(1);
    }
}
