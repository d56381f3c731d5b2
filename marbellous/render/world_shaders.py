"""GLSL of the world renderer: instanced lit solids with sun shadows, their shadow depth pass, ray-cast
spheres (particles) lit and shadowed alike, and lines and dots of constant pixel size.  Surfaces (cloth) are
drawn by the solids' programs too, as one instance of the identity with a colour per vertex.

The solids' lighting follows the game renderer's (``renderer.py``): a sun with a shadow map filtered over
3 x 3 texels in four hardware-compared bilinear fetches (the same GLSL, ``shadow_map.py``), a sky
term from the normal's height, a small specular highlight; distances (grid cell, fog) are uniforms so any
scale of world reads well.  A face seen from behind is lit with its normal turned to the
eye, and a thin sheet (pattern 3, cloth) lets part of the sun that falls on one face through to the other.
"""
from .shadow_map import SHADOW_GLSL

#: The fraction of the sunlight on one face of a thin sheet (cloth) that shows on the other (GLSL
#: ``SHEET_THROUGH``; the game's renderer lights its cloth flag alike).
SHEET_THROUGH = 0.45
#: The GLSL declaration of :data:`SHEET_THROUGH`.
SHEET_THROUGH_GLSL = f"""
const float SHEET_THROUGH = {SHEET_THROUGH!r};
"""
# The shadow lookup's depth bias (``shadow_map.py``), in the map's 0..1 depth: the map's depth spans 8 times the
# half-width of the region it covers, so 0.002 is 1.6 % of that half-width where a surface faces the sun edge-on.
_SHADOW_BIAS = """
const float SHADOW_BIAS = 0.002;
"""

SOLID_VS = """
#version 330
uniform mat4 u_view_proj;
uniform mat4 u_light_view_proj;
in vec3 in_pos;
in vec3 in_normal;
in mat4 in_model;               // per instance (a surface: one instance, the identity)
in vec4 in_color;               // rgb, pattern code; per instance (a surface: per vertex)
out vec3 v_world;
out vec3 v_local;
out vec3 v_normal;
out vec4 v_light;
out vec3 v_color;
flat out int v_pattern;
void main() {
    vec4 world = in_model * vec4(in_pos, 1.0);
    v_world = world.xyz;
    v_local = in_pos;
    v_normal = mat3(in_model) * in_normal;
    v_light = u_light_view_proj * world;
    v_color = in_color.rgb;
    v_pattern = int(in_color.a + 0.5);
    gl_Position = u_view_proj * world;
}
"""

# The lighting of every lit surface (solids and spheres): the sun, shadowed through the shadow map's tent lookup
# (``shadow_map.py``), a sky term, a small highlight and fog.  SHADOW_GLSL and _SHADE both need _SUN before them.
_SUN = """
uniform vec3 u_sun;             // unit vector towards the sun
"""

_SHADE = """
uniform vec3 u_eye;
uniform float u_alpha;
uniform vec2 u_fog;             // distance where fog starts, and over which it thickens fully (m)
uniform vec3 u_background;

// colour of a surface of colour base with unit normal n at world point p, reached by the fraction sun of
// the sunlight; a thin sheet lets the fraction through of the sunlight on its other face through (diffusely,
// Lambert's cosine on the lit face), a solid none
vec4 shade(vec3 base, vec3 n, vec3 p, float sun, float through) {
    float lit = max(dot(n, u_sun), 0.0) * sun;
    float diffuse = lit + through * max(-dot(n, u_sun), 0.0) * sun;
    float sky = 0.5 + 0.5 * n.y;
    vec3 v = normalize(u_eye - p);
    float spec = pow(max(dot(reflect(-u_sun, n), v), 0.0), 24.0) * 0.18 * lit;
    vec3 c = base * (0.30 * sky + 0.14 + 0.74 * diffuse) + vec3(spec);
    float fog = clamp((length(u_eye - p) - u_fog.x) / u_fog.y, 0.0, 1.0);
    return vec4(mix(pow(c, vec3(1.0 / 1.1)), u_background, fog), u_alpha);
}
"""

SOLID_FS = """
#version 330
""" + _SUN + _SHADOW_BIAS + SHADOW_GLSL + _SHADE + """
uniform float u_grid;           // grid cell (m)
""" + SHEET_THROUGH_GLSL + """
in vec3 v_world;
in vec3 v_local;
in vec3 v_normal;
in vec4 v_light;
in vec3 v_color;
flat in int v_pattern;          // 0 plain, 1 grid, 2 octants, 3 a thin sheet (plain)
out vec4 f_color;

void main() {
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;
    vec3 base = v_color;
    if (v_pattern == 1) {
        vec3 an = abs(n);
        vec2 uv = (an.y >= max(an.x, an.z) ? v_world.xz : (an.x >= an.z ? v_world.yz : v_world.xy)) / u_grid;
        vec2 fw = fwidth(uv);
        vec2 g = abs(fract(uv + 0.5) - 0.5);
        vec2 on = 1.0 - smoothstep(vec2(0.0), 1.5 * fw, g);
        float line = max(on.x, on.y) * (1.0 - smoothstep(0.1, 0.35, max(fw.x, fw.y)));
        base *= 1.0 - 0.25 * line;
    } else if (v_pattern == 2) {
        vec3 d = v_local;
        base = d.x * d.y * d.z > 0.0 ? v_color : v_color * 0.55;
    }
    float sun = shadow_factor(v_light, n, SHADOW_BIAS, 0.0);
    f_color = shade(base, n, v_world, sun, v_pattern == 3 ? SHEET_THROUGH : 0.0);
}
"""

DEPTH_VS = """
#version 330
uniform mat4 u_light_view_proj;
in vec3 in_pos;
in mat4 in_model;
void main() { gl_Position = u_light_view_proj * in_model * vec4(in_pos, 1.0); }
"""

DEPTH_FS = """
#version 330
void main() {}
"""

# Lines: each segment becomes a screen-space quad of in_width pixels (clipped at the near plane first).
LINES_VS = """
#version 330
uniform mat4 u_view_proj;
in vec3 in_pos;
in vec3 in_color;
in float in_width;
out vec3 g_color;
out float g_width;
void main() { g_color = in_color; g_width = in_width; gl_Position = u_view_proj * vec4(in_pos, 1.0); }
"""

LINES_GS = """
#version 330
layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;
uniform vec2 u_viewport;        // pixels
in vec3 g_color[];
in float g_width[];
out vec3 v_color;

void corner(vec4 p, vec2 offset) {
    gl_Position = vec4(p.xy + offset * 2.0 / u_viewport * p.w, p.z, p.w);
    v_color = g_color[0];
    EmitVertex();
}

void main() {
    vec4 a = gl_in[0].gl_Position;
    vec4 b = gl_in[1].gl_Position;
    float da = a.z + a.w;       // > 0 in front of the near plane
    float db = b.z + b.w;
    if (da < 0.0 && db < 0.0) return;
    if (da < 0.0) a = mix(a, b, da / (da - db));
    else if (db < 0.0) b = mix(b, a, db / (db - da));
    vec2 d = (b.xy / b.w - a.xy / a.w) * u_viewport;
    vec2 along = length(d) > 1e-6 ? normalize(d) : vec2(1.0, 0.0);
    vec2 across = vec2(-along.y, along.x) * 0.5 * g_width[0];
    along *= 0.5 * g_width[0];
    corner(a, -across - along);
    corner(a, across - along);
    corner(b, -across + along);
    corner(b, across + along);
    EndPrimitive();
}
"""

# (u_behind: lines in the scene drawn after the FXAA pass, with no depth buffer of the scene's to test, are hidden
# where the scene's depth, read from its texture, is nearer)
LINES_FS = """
#version 330
uniform bool u_behind;          // discard fragments behind u_depth's
uniform sampler2D u_depth;      // the scene's depth, pixel for pixel
in vec3 v_color;
out vec4 f_color;
void main() {
    if (u_behind && gl_FragCoord.z > texelFetch(u_depth, ivec2(gl_FragCoord.xy), 0).r) discard;
    f_color = vec4(v_color, 1.0);
}
"""

# Dots: each point becomes a disc of in_size pixels with a dark rim.
POINTS_VS = """
#version 330
uniform mat4 u_view_proj;
in vec3 in_pos;
in vec3 in_color;
in float in_size;
out vec3 g_color;
out float g_size;
void main() { g_color = in_color; g_size = in_size; gl_Position = u_view_proj * vec4(in_pos, 1.0); }
"""

POINTS_GS = """
#version 330
layout(points) in;
layout(triangle_strip, max_vertices = 4) out;
uniform vec2 u_viewport;
in vec3 g_color[];
in float g_size[];
out vec3 v_color;
out vec2 v_uv;
void main() {
    vec4 p = gl_in[0].gl_Position;
    if (p.z + p.w < 0.0) return;
    for (int k = 0; k < 4; k++) {
        vec2 uv = vec2(k % 2 == 0 ? -1.0 : 1.0, k < 2 ? -1.0 : 1.0);
        gl_Position = vec4(p.xy + uv * g_size[0] / u_viewport * p.w, p.z, p.w);
        v_color = g_color[0];
        v_uv = uv;
        EmitVertex();
    }
    EndPrimitive();
}
"""

POINTS_FS = """
#version 330
in vec3 v_color;
in vec2 v_uv;
out vec4 f_color;
void main() {
    float r = length(v_uv);
    if (r > 1.0) discard;
    f_color = vec4(r > 0.7 ? v_color * 0.25 : v_color, 1.0);
}
"""

# Spheres: each centre becomes a quad facing the eye that just covers the sphere's outline, in the plane
# that touches the sphere's nearest point (the cone of sight lines touching the sphere, cut by that
# plane); each fragment casts its sight line at the sphere, discards a miss and is lit at the hit point.
# The shadow map is read once per sphere, around its sunlit pole: a particle is in the shade or in the sun
# as a whole, and the fragments (many per sphere in a heap, drawn over one another) skip the four fetches.
# Distances are taken from the centre, so a 1 cm particle seen from 100 m keeps its precision in float32.
# The fragment keeps the quad's depth, its nearest point's, rather than writing the hit point's: a
# written depth turns off the early depth test, and a heap of particles (sent near to far) would then be
# shaded some twenty layers deep (six times slower on llvmpipe without multisampling).  So spheres of one
# size hide one another exactly, and a sphere hides and is hidden by anything else exactly unless it is
# nearer to it than its radius (a wall it leans on), where its outline may show a little in front.  A
# sphere smaller than a pixel is drawn a pixel wide, so far particles do not vanish.
SPHERES_VS = """
#version 330
in vec3 in_center;
in float in_radius;
in vec3 in_color;
out vec3 g_center;
out float g_radius;
out vec3 g_color;
void main() { g_center = in_center; g_radius = in_radius; g_color = in_color; gl_Position = vec4(in_center, 1.0); }
"""

SPHERES_GS = """
#version 330
layout(points) in;
layout(triangle_strip, max_vertices = 4) out;
uniform mat4 u_view_proj;
uniform mat4 u_light_view_proj;
uniform vec3 u_eye;""" + _SUN + _SHADOW_BIAS + SHADOW_GLSL + """
uniform float u_pixel;          // the side of a pixel, per metre from the eye
in vec3 g_center[];
in float g_radius[];
in vec3 g_color[];
out vec3 v_world;
flat out vec3 v_center;
flat out float v_radius;
flat out vec3 v_color;
flat out float v_sun;
flat out float v_sharp;
void main() {
    vec3 c = g_center[0];
    vec3 w = c - u_eye;
    float d = length(w);
    if (d <= 1.0001 * g_radius[0]) return;      // the eye is inside
    float r = max(g_radius[0], u_pixel * d);
    float sharp = clamp(0.5 * (r / (u_pixel * d) - 1.0), 0.0, 1.0);
    w /= d;
    vec3 u = normalize(cross(w, abs(w.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0)));
    vec3 v = cross(u, w);
    float h = r * (d - r) / sqrt(d * d - r * r);   // the outline's radius in the plane touching the sphere
    // (the four fetches spread over the sphere's sunlit cap, half a radius off its pole: the map's coordinates run over
    // 2 / |the light matrix's first row| metres)
    float per_metre = 0.5 * length(vec3(u_light_view_proj[0][0], u_light_view_proj[1][0], u_light_view_proj[2][0]));
    float sun = shadow_factor(u_light_view_proj * vec4(c + g_radius[0] * u_sun, 1.0), u_sun, SHADOW_BIAS,
                              0.5 * g_radius[0] * per_metre);
    for (int k = 0; k < 4; k++) {
        vec3 p = c - r * w + h * ((k % 2 == 0 ? -1.0 : 1.0) * u + (k < 2 ? -1.0 : 1.0) * v);
        gl_Position = u_view_proj * vec4(p, 1.0);
        v_world = p;
        v_center = c;
        v_radius = r;
        v_color = g_color[0];
        v_sun = sun;
        v_sharp = sharp;
        EmitVertex();
    }
    EndPrimitive();
}
"""

SPHERES_FS = """
#version 330
""" + _SUN + _SHADE + """
in vec3 v_world;
flat in vec3 v_center;
flat in float v_radius;
flat in vec3 v_color;
flat in float v_sun;
flat in float v_sharp;          // 0 for a sphere a pixel wide, 1 from three pixels up
out vec4 f_color;
void main() {
    vec3 dir = normalize(v_world - u_eye);
    vec3 q = v_world - v_center;
    vec3 perp = q - dot(q, dir) * dir;          // from the centre to the sight line's nearest point
    float r2 = v_radius * v_radius;
    float d2 = dot(perp, perp);
    if (d2 > r2) discard;
    vec3 n = (perp - sqrt(r2 - d2) * dir) / v_radius;
    vec3 p = v_center + v_radius * n;
    // a sphere a few pixels wide is shaded with normals bent towards the eye: a pixel's centre is no fair
    // sample of the part of the sphere the pixel covers, and a 1-pixel particle would take the colour of
    // whichever edge the centre falls on
    f_color = shade(v_color, normalize(mix(-dir, n, v_sharp)), p, v_sun, 0.0);
}
"""

# The spheres' shadow pass: a disc of the sphere's radius across the (parallel) sunlight, through its centre
# (the sunlit half is in front of it, so a sphere does not shadow itself where the sun reaches it).
SPHERES_DEPTH_VS = """
#version 330
in vec3 in_center;
in float in_radius;
out vec3 g_center;
out float g_radius;
void main() { g_center = in_center; g_radius = in_radius; gl_Position = vec4(in_center, 1.0); }
"""

SPHERES_DEPTH_GS = """
#version 330
layout(points) in;
layout(triangle_strip, max_vertices = 4) out;
uniform mat4 u_light_view_proj;
uniform vec3 u_light_right;     // the light view's right and up axes (world)
uniform vec3 u_light_up;
in vec3 g_center[];
in float g_radius[];
out vec2 v_uv;
void main() {
    for (int k = 0; k < 4; k++) {
        vec2 uv = vec2(k % 2 == 0 ? -1.0 : 1.0, k < 2 ? -1.0 : 1.0);
        vec3 p = g_center[0] + g_radius[0] * (uv.x * u_light_right + uv.y * u_light_up);
        gl_Position = u_light_view_proj * vec4(p, 1.0);
        v_uv = uv;
        EmitVertex();
    }
    EndPrimitive();
}
"""

SPHERES_DEPTH_FS = """
#version 330
in vec2 v_uv;
void main() {
    if (dot(v_uv, v_uv) > 1.0) discard;
}
"""
