"""GLSL of the world renderer: instanced lit solids with sun shadows, their shadow depth pass, and lines
and dots of constant pixel size drawn over the scene.

The solids' lighting follows the game renderer's (``renderer.py``): a sun with a 3 x 3 PCF shadow
map, a sky term from the normal's height, a small specular highlight; distances (grid cell, fog) are
uniforms so any scale of world reads well.
"""

SOLID_VS = """
#version 330
uniform mat4 u_view_proj;
uniform mat4 u_light_view_proj;
in vec3 in_pos;
in vec3 in_normal;
in mat4 in_model;
in vec4 in_color;               // rgb, pattern code
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

SOLID_FS = """
#version 330
uniform vec3 u_sun;             // unit vector towards the sun
uniform vec3 u_eye;
uniform sampler2D u_shadow;
uniform float u_alpha;
uniform float u_grid;           // grid cell (m)
uniform vec2 u_fog;             // distance where fog starts, and over which it thickens fully (m)
uniform vec3 u_background;
in vec3 v_world;
in vec3 v_local;
in vec3 v_normal;
in vec4 v_light;
in vec3 v_color;
flat in int v_pattern;          // 0 plain, 1 grid, 2 octants
out vec4 f_color;

float shadow_factor(vec3 n) {
    vec3 p = v_light.xyz / v_light.w * 0.5 + 0.5;
    if (p.x < 0.0 || p.x > 1.0 || p.y < 0.0 || p.y > 1.0 || p.z > 1.0) return 1.0;
    vec2 texel = 1.0 / vec2(textureSize(u_shadow, 0));
    float bias = max(0.002 * (1.0 - dot(n, u_sun)), 0.0004);
    float lit = 0.0;
    for (int i = -1; i <= 1; i++)
        for (int j = -1; j <= 1; j++)
            lit += (p.z - bias > texture(u_shadow, p.xy + vec2(i, j) * texel).r) ? 0.0 : 1.0;
    return lit / 9.0;
}

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
    float diffuse = max(dot(n, u_sun), 0.0) * shadow_factor(n);
    float sky = 0.5 + 0.5 * n.y;
    vec3 v = normalize(u_eye - v_world);
    float spec = pow(max(dot(reflect(-u_sun, n), v), 0.0), 24.0) * 0.18 * diffuse;
    vec3 c = base * (0.30 * sky + 0.14 + 0.74 * diffuse) + vec3(spec);
    float fog = clamp((length(u_eye - v_world) - u_fog.x) / u_fog.y, 0.0, 1.0);
    c = mix(pow(c, vec3(1.0 / 1.1)), u_background, fog);
    f_color = vec4(c, u_alpha);
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

LINES_FS = """
#version 330
in vec3 v_color;
out vec4 f_color;
void main() { f_color = vec4(v_color, 1.0); }
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
