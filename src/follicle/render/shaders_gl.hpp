#pragma once
// GLSL 3.30 core sources of the renderer (internal). Conventions: world space in metres,
// linear RGB; light directions point towards the light; a white Lambertian surface facing a
// light of intensity 1 has radiance 1 (the pi of the BRDF is folded into the light).
namespace follicle::render::glsl {

inline constexpr const char* kLightsBlock = R"(
const int MAX_LIGHTS = 8;
uniform int uNumLights;
uniform vec3 uLightDir[MAX_LIGHTS];    // unit, towards the light
uniform vec3 uLightColor[MAX_LIGHTS];  // colour * intensity
uniform vec3 uAmbientColor;
uniform vec3 uEye;
)";

inline constexpr const char* kMeshVs = R"(
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUV;
layout(location = 3) in vec3 aColor;
layout(location = 4) in vec3 aPu;
layout(location = 5) in vec3 aPv;
uniform mat4 uModel;
uniform mat3 uNormalMat;
uniform mat4 uViewProj;
out vec3 vPos;
out vec3 vNormal;
out vec2 vUV;
out vec3 vColor;
out vec3 vPu;
out vec3 vPv;
void main() {
  vec4 w = uModel * vec4(aPos, 1.0);
  vPos = w.xyz;
  vNormal = uNormalMat * aNormal;
  vUV = aUV;
  vColor = aColor;
  vPu = mat3(uModel) * aPu;
  vPv = mat3(uModel) * aPv;
  gl_Position = uViewProj * w;
}
)";

// Features are compile-time (#define SHADING 0|1|2, HAS_ALBEDO, HAS_HEIGHT, HAS_NORMALMAP,
// HAS_SHADOW, HAS_LIGHTMAP): llvmpipe runs both sides of data-dependent branches, so texture
// fetches behind a run-time flag would cost as much as taken ones.
inline constexpr const char* kMeshFs = R"(
in vec3 vPos;
in vec3 vNormal;
in vec2 vUV;
in vec3 vColor;
in vec3 vPu;
in vec3 vPv;
out vec4 fragColor;
uniform vec3 uBaseColor;
uniform bool uUseVertexColor;
uniform sampler2D uAlbedoTex;
uniform sampler2D uHeightTex;
uniform vec2 uHeightTexel;
uniform float uBumpStrength;
uniform sampler2D uNormalTex;
uniform float uSpecular;
uniform float uShininess;
uniform float uAmbient;
uniform int uShadowLight;  // index of the shadowing light
uniform sampler2DShadow uShadowTex;
uniform mat4 uLightVP;
uniform float uShadowTexel;       // 1 / shadow map size
uniform float uShadowNormalOffset; // [m]
uniform float uShadowBias;        // in depth-buffer units
uniform int uNumLobes;
uniform vec3 uCxy[4];
uniform vec3 uCz[4];
uniform vec3 uN[4];

#ifdef HAS_LIGHTMAP
uniform sampler2D uLightMap;  // light through the hair (Bando 2003 §3.4, line 12), uLightVP
float light_map(vec3 p) {
  vec4 c = uLightVP * vec4(p, 1.0);
  vec2 s = c.xy / c.w * 0.5 + 0.5;
  if (s.x < 0.0 || s.x > 1.0 || s.y < 0.0 || s.y > 1.0) return 1.0;
  return texture(uLightMap, s).r;
}
#endif

#ifdef HAS_SHADOW
float shadow_factor(vec3 p, vec3 ng) {
  vec4 c = uLightVP * vec4(p + ng * uShadowNormalOffset, 1.0);
  vec3 s = c.xyz / c.w * 0.5 + 0.5;
  if (s.x < 0.0 || s.x > 1.0 || s.y < 0.0 || s.y > 1.0 || s.z > 1.0) return 1.0;
  // 4 bilinear PCF taps at +-0.5 texel: a smooth 3x3-texel footprint for 4 lookups.
  float sum = 0.0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      sum += texture(uShadowTex, vec3(s.xy + (vec2(i, j) - 0.5) * uShadowTexel, s.z - uShadowBias));
  return 0.25 * sum;
}
#endif

// docs/skin-constants.md §4.1: f = rho_d/pi + sum_k max(0, Cxy (wo.x wi.x + wo.y wi.y) + Cz wo.z wi.z)^n
vec3 lafortune(vec3 albedo, vec3 n, vec3 wo, vec3 wi) {
  float z = dot(wo, n) * dot(wi, n);
  float xy = dot(wo, wi) - z;
  vec3 f = albedo / 3.14159265;
  for (int k = 0; k < uNumLobes; ++k) f += pow(max(uCxy[k] * xy + uCz[k] * z, vec3(0.0)), uN[k]);
  return f;
}

void main() {
  vec3 ng = normalize(vNormal);
  if (!gl_FrontFacing) ng = -ng;
  vec3 N = ng;
  vec2 tc = vec2(vUV.x, 1.0 - vUV.y);  // image row 0 is the top (v = 1)
#if defined(HAS_HEIGHT) || defined(HAS_NORMALMAP)
  vec3 puv = cross(vPu, vPv);
  float orient = dot(puv, ng) < 0.0 ? -1.0 : 1.0;
  float area = max(length(puv), 1e-20);
#endif
#ifdef HAS_HEIGHT
  // Blinn 1978 bump mapping: N' = N + (Fu (N x Pv) - Fv (N x Pu)) / |Pu x Pv|
  float fu = (texture(uHeightTex, tc + vec2(uHeightTexel.x, 0.0)).r -
              texture(uHeightTex, tc - vec2(uHeightTexel.x, 0.0)).r) / (2.0 * uHeightTexel.x);
  float fv = -(texture(uHeightTex, tc + vec2(0.0, uHeightTexel.y)).r -
               texture(uHeightTex, tc - vec2(0.0, uHeightTexel.y)).r) / (2.0 * uHeightTexel.y);
  N = normalize(N + uBumpStrength * orient * (fu * cross(N, vPv) - fv * cross(N, vPu)) / area);
#endif
#ifdef HAS_NORMALMAP
  vec3 t = texture(uNormalTex, tc).xyz;
  vec3 T = vPu - N * dot(N, vPu);
  T = dot(T, T) > 1e-30 ? normalize(T) : normalize(cross(N, abs(N.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0)));
  vec3 B = cross(N, T) * orient;
  N = normalize(t.x * T + t.y * B + t.z * N);
#endif
  vec3 albedo = uUseVertexColor ? vColor : uBaseColor;
#ifdef HAS_ALBEDO
  albedo *= texture(uAlbedoTex, tc).rgb;
#endif
#if SHADING == 2
  fragColor = vec4(albedo, 1.0);
#else
  vec3 V = normalize(uEye - vPos);
  vec3 col = albedo * uAmbient * uAmbientColor;
#ifdef HAS_SHADOW
  float shadow = shadow_factor(vPos, ng);
#ifdef HAS_LIGHTMAP
  shadow *= light_map(vPos);  // line 16: shadow and light mapping
#endif
#endif
  for (int i = 0; i < uNumLights; ++i) {
    vec3 L = uLightDir[i];
    float ndl = max(dot(N, L), 0.0);
    vec3 E = uLightColor[i];
#ifdef HAS_SHADOW
    if (i == uShadowLight) E *= shadow;
#endif
#if SHADING == 1
    col += 3.14159265 * lafortune(albedo, N, V, L) * ndl * E;
#else
    vec3 H = normalize(L + V);
    float spec = ndl > 0.0 ? uSpecular * pow(max(dot(N, H), 0.0), uShininess) : 0.0;
    col += (albedo * ndl + vec3(spec)) * E;
#endif
  }
  fragColor = vec4(col, 1.0);
#endif
}
)";

// Strands: with RIBBONS defined the vertex shader feeds a geometry shader that expands each
// segment into a screen-space quad of per-vertex width; otherwise plain GL lines.
inline constexpr const char* kStrandVs = R"(
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aColor;
layout(location = 2) in vec3 aTangent;
layout(location = 3) in float aRadius;  // [m] in model units, < 0: use uWidthPx
uniform mat4 uModel;
uniform mat4 uViewProj;
uniform float uPixelScale;  // framebuffer pixels per (metre / depth)
uniform float uModelScale;
uniform float uWidthPx;     // framebuffer pixels
#ifdef RIBBONS
out vec3 vPos;
out vec3 vColor;
out vec3 vTangent;
out float vWidth;
#else
out vec3 fPos;
out vec3 fColor;
out vec3 fTangent;
out float fAlpha;
#endif
void main() {
  vec4 w = uModel * vec4(aPos, 1.0);
  gl_Position = uViewProj * w;
#ifdef RIBBONS
  vPos = w.xyz;
  vColor = aColor;
  vTangent = mat3(uModel) * aTangent;
  vWidth = aRadius >= 0.0 ? 2.0 * aRadius * uModelScale * uPixelScale / max(gl_Position.w, 1e-6)
                          : uWidthPx;
#else
  fPos = w.xyz;
  fColor = aColor;
  fTangent = mat3(uModel) * aTangent;
  fAlpha = 1.0;
#endif
}
)";

inline constexpr const char* kStrandGs = R"(
layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;
in vec3 vPos[];
in vec3 vColor[];
in vec3 vTangent[];
in float vWidth[];
uniform vec2 uViewport;
out vec3 fPos;
out vec3 fColor;
out vec3 fTangent;
out float fAlpha;
void main() {
  vec4 c0 = gl_in[0].gl_Position, c1 = gl_in[1].gl_Position;
  if (c0.w <= 1e-6 || c1.w <= 1e-6) return;
  vec2 half_vp = 0.5 * uViewport;
  vec2 d = c1.xy / c1.w * half_vp - c0.xy / c0.w * half_vp;
  float l = length(d);
  vec2 n = l > 1e-6 ? vec2(-d.y, d.x) / l : vec2(1.0, 0.0);
  for (int i = 0; i < 2; ++i) {
    vec4 c = gl_in[i].gl_Position;
    // Thinner than a framebuffer pixel: draw 1 px wide with proportional opacity.
    float w = max(vWidth[i], 1.0);
    vec2 off = n * (0.5 * w) / half_vp * c.w;
    fPos = vPos[i];
    fColor = vColor[i];
    fTangent = vTangent[i];
    fAlpha = min(vWidth[i], 1.0);
    gl_Position = c + vec4(off, 0.0, 0.0);
    EmitVertex();
    gl_Position = c - vec4(off, 0.0, 0.0);
    EmitVertex();
  }
  EndPrimitive();
}
)";

inline constexpr const char* kStrandFs = R"(
in vec3 fPos;
in vec3 fColor;
in vec3 fTangent;
in float fAlpha;
out vec4 fragColor;
uniform int uShading;  // 0 vertex colour, 1 Kajiya-Kay
uniform float uDiffuse;
uniform float uSpecular;
uniform float uShininess;
uniform float uAmbient;
uniform float uOpacity;
void main() {
  vec3 c = fColor;
  if (uShading == 1) {
    vec3 T = normalize(fTangent);
    vec3 V = normalize(uEye - fPos);
    vec3 col = c * uAmbient * uAmbientColor;
    float tv = dot(T, V);
    float sv = sqrt(max(0.0, 1.0 - tv * tv));
    for (int i = 0; i < uNumLights; ++i) {
      float tl = dot(T, uLightDir[i]);
      float sl = sqrt(max(0.0, 1.0 - tl * tl));
      // Kajiya-Kay 1989: diffuse ~ sin(T, L); specular ~ (sin(T,L) sin(T,V) - (T.L)(T.V))^p
      float spec = pow(max(0.0, sl * sv - tl * tv), uShininess);
      col += uLightColor[i] * (uDiffuse * sl * c + uSpecular * spec);
    }
    c = col;
  }
  fragColor = vec4(c, uOpacity * fAlpha);
}
)";

inline constexpr const char* kDepthVs = R"(
layout(location = 0) in vec3 aPos;
uniform mat4 uModel;
uniform mat4 uLightVP;
void main() { gl_Position = uLightVP * (uModel * vec4(aPos, 1.0)); }
)";

inline constexpr const char* kDepthFs = R"(
out vec4 fragColor;
void main() { fragColor = vec4(1.0); }
)";

inline constexpr const char* kParticleVs = R"(
layout(location = 0) in vec2 aCorner;
layout(location = 1) in vec3 iPos;
layout(location = 2) in vec3 iColor;
layout(location = 3) in float iRadius;
layout(location = 4) in float iOpacity;
layout(location = 5) in vec3 iDir;
uniform mat4 uModel;
uniform mat4 uView;
uniform mat4 uProj;
uniform float uModelScale;
uniform int uShading;  // 0 flat disc, 1 hair splat
out vec2 pCorner;
out vec3 pColor;
out float pOpacity;
void main() {
  vec4 vc = uView * uModel * vec4(iPos, 1.0);
  float r = iRadius * uModelScale;
  vec2 ax = vec2(1.0, 0.0), ay = vec2(0.0, 1.0);
  vec2 ext = vec2(r);
  if (uShading == 1) {
    // Billboard aligned with the projected particle direction (Bando 2003 §3.4).
    vec3 dv = mat3(uView) * (mat3(uModel) * iDir);
    float l = length(dv.xy);
    if (l > 1e-6) {
      ax = dv.xy / l;
      ay = vec2(-ax.y, ax.x);
    }
    ext = vec2(2.0 * r, 0.6 * r);
  }
  vec2 off = aCorner.x * ext.x * ax + aCorner.y * ext.y * ay;
  gl_Position = uProj * vec4(vc.xy + off, vc.z, 1.0);
  pCorner = aCorner;
  pColor = iColor;
  pOpacity = iOpacity;
}
)";

inline constexpr const char* kParticleFs = R"(
in vec2 pCorner;
in vec3 pColor;
in float pOpacity;
uniform int uShading;
out vec4 fragColor;
void main() {
  float a;
  if (uShading == 1) {
    // Procedural hair texture: soft across, fading towards the ends, with fibre streaks.
    a = (1.0 - pCorner.x * pCorner.x) * exp(-3.0 * pCorner.y * pCorner.y) *
        (0.75 + 0.25 * cos(pCorner.y * 14.0));
  } else {
    float d = length(pCorner);
    if (d > 1.0) discard;
    a = clamp((1.0 - d) / max(fwidth(d), 1e-4), 0.0, 1.0);
  }
  fragColor = vec4(pColor, pOpacity * a);
}
)";

inline constexpr const char* kResolveVs = R"(
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

// Box filter k x k supersamples in linear space, then encode sRGB.
inline constexpr const char* kResolveFs = R"(
uniform sampler2D uSrc;
uniform int uK;
uniform bool uUnpremultiply;
out vec4 fragColor;
void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * uK;
  vec4 s = vec4(0.0);
  for (int j = 0; j < uK; ++j)
    for (int i = 0; i < uK; ++i) s += texelFetch(uSrc, base + ivec2(i, j), 0);
  s /= float(uK * uK);
  vec3 c = s.rgb;
  if (uUnpremultiply) c = s.a > 0.0 ? c / s.a : vec3(0.0);
  c = clamp(c, 0.0, 1.0);
  c = mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
  fragColor = vec4(c, clamp(s.a, 0.0, 1.0));
}
)";

}  // namespace follicle::render::glsl
