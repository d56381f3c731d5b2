"""The sun's shadow map of both renderers: a depth texture that compares in hardware, and the GLSL that reads it
through a 3 x 3 texel tent filter in four fetches."""
import moderngl

#: GLSL: the ``u_shadow`` sampler and ``float shadow_factor(vec4 light, vec3 n, float bias, float spread)``, the
#: sun's share (0 in shadow, 1 lit) reaching a point at ``light`` (its position in the light's clip space) with
#: unit normal ``n``: its depth is lowered by ``bias`` (in the map's 0..1 depth) where the surface faces the sun
#: edge-on, down to a fifth of it where it faces the sun, and the four fetches are at least ``spread`` (in the
#: map's 0..1 coordinates) off the point.  Needs ``uniform vec3 u_sun`` (unit vector towards the sun) before it.
SHADOW_GLSL = """
uniform sampler2DShadow u_shadow;

// The map compares in hardware: with linear filtering one fetch blends the 0-or-1 tests of the 2 x 2 texels
// around the point (bilinear PCF).  Four such fetches half a texel diagonally off the point cover its 3 x 3 texels
// with weights 1 2 1 / 2 4 2 / 1 2 1 (a tent): 16 depth comparisons in four fetches, where nine nearest taps took
// nine.  (In a geometry shader texture() reads the map's only level, as in a fragment shader.)
float shadow_factor(vec4 light, vec3 n, float bias, float spread) {
    vec3 p = light.xyz / light.w * 0.5 + 0.5;
    if (p.x < 0.0 || p.x > 1.0 || p.y < 0.0 || p.y > 1.0 || p.z > 1.0) return 1.0;
    float z = p.z - max(bias * (1.0 - dot(n, u_sun)), 0.2 * bias);
    vec2 d = max(0.5 / vec2(textureSize(u_shadow, 0)), vec2(spread));
    return 0.25 * (texture(u_shadow, vec3(p.xy + vec2(-d.x, -d.y), z))
                   + texture(u_shadow, vec3(p.xy + vec2(d.x, -d.y), z))
                   + texture(u_shadow, vec3(p.xy + vec2(-d.x, d.y), z))
                   + texture(u_shadow, vec3(p.xy + d, z)));
}
"""


def shadow_map(ctx, side):
    """``(texture, framebuffer)``: a ``side`` x ``side`` texel depth texture of the moderngl ``ctx`` that
    :data:`SHADOW_GLSL` reads (compared ``<=``: lit where the fragment's depth is at most the map's; linearly
    filtered), and the framebuffer that draws depth into it."""
    texture = ctx.depth_texture((side, side))
    texture.compare_func = "<="
    texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
    return texture, ctx.framebuffer(depth_attachment=texture)
