#version 450 core
// The heatmap's primary rays traced on the GPU over the binary BVH's flat
// node array (ui/render/gpu_trace.cpp drives it). One invocation per pixel
// of the row band [u_row0, u_row_end) (the whole image in one dispatch, or
// band by band across the GUI's frames; a pixel's result does not depend on
// its band);
// it reproduces, operation for operation, what the CPU's instrumented
// traversal counts (core/accel/bvh/bvh.cpp, traverse<closest, Ordered,
// Collect = true, Test>):
//  - the primary ray of core/query/camera.cpp primary_ray (the per-camera
//    constants tan(yfov/2), aspect and right = forward x up come in as
//    uniforms, computed by the same C++ code);
//  - the robust slab test of core/math/aabb.h (sign-selected near plane,
//    NaN-ignoring updates, exit distance scaled by kSlabExitScale);
//  - the watertight test of core/geometry/triangle.cpp with its double
//    precision fallbacks, or Moller-Trumbore;
//  - the same child order, stack order, culling and counters.
// Every value is `precise` and written in the C++ evaluation order, so that
// the compiler neither contracts a multiply and an add into an FMA nor
// reassociates, and divisions and square roots are correctly rounded
// (div_rn, sqrt_rn): on llvmpipe and on an NVIDIA H200 (2026-12-04) the
// results are bit for bit the CPU's. tests/gl/test_gpu_trace.cpp checks that
// on llvmpipe, accelviz_gpu_bench on any device.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

// core/accel/bvh/bvh.h BvhNode: 32 bytes, std430 with scalar members only.
struct Node {
  float lo_x, lo_y, lo_z;
  float hi_x, hi_y, hi_z;
  uint index;  // inner: first child (children at index, index + 1); leaf: first triangle
  uint count;  // 0: inner node
};
// core/geometry/triangle.h Triangle in leaf order: 36 bytes.
struct Tri {
  float v[9];
};
// Per pixel: the RayStats counters and the hit (leaf-order position, t).
struct PixelOut {
  uint nodes_visited;
  uint box_tests;
  uint prim_tests;
  uint nodes_culled;
  uint nodes_missed;
  uint prim;  // leaf-order position of the closest hit; 0xFFFFFFFF: miss
  float t;    // hit distance; +inf on a miss
  uint pad;
};

layout(std430, binding = 0) readonly buffer Nodes { Node nodes[]; };
layout(std430, binding = 1) readonly buffer Tris { Tri tris[]; };
layout(std430, binding = 2) writeonly buffer Out { PixelOut pixels[]; };

uniform int u_width;
uniform int u_height;
uniform int u_row0;     // first row of this dispatch's band
uniform int u_row_end;  // one past its last row (<= u_height)
uniform uint u_node_count;
uniform vec3 u_position;
uniform vec3 u_forward;
uniform vec3 u_up;
uniform vec3 u_right;         // cross(forward, up), as camera_ray computes it
uniform float u_tan_half;     // std::tan(0.5f * yfov)
uniform float u_aspect;       // camera_aspect(cam, W, H)
uniform float u_slab_scale;   // kSlabExitScale
uniform int u_ordered;        // QueryOptions::ordered
uniform int u_back_to_front;  // QueryOptions::back_to_front
uniform int u_xray;           // QueryOptions::xray
uniform int u_watertight;     // TriangleTest::watertight (else Moller-Trumbore)

const uint kInvalid = 0xFFFFFFFFu;
const float kWatertightLowRange = 1e-30;
const int kMaxDepth = 64;  // kBvhMaxDepth

float inf_f() { return uintBitsToFloat(0x7F800000u); }
bool finite_f(float x) { return !isinf(x) && !isnan(x); }
bool finite_d(double x) { return !isinf(x) && !isnan(x); }

vec3 vert(uint k, int i) { return vec3(tris[k].v[3 * i], tris[k].v[3 * i + 1], tris[k].v[3 * i + 2]); }

// ---- ray --------------------------------------------------------------------

vec3 g_origin;
vec3 g_dir;
vec3 g_inv;
float g_tmin;
float g_tmax;
// WatertightRay
int g_kx, g_ky, g_kz;
float g_sx, g_sy, g_sz;

// Correctly rounded float division and square root. GLSL (4.50, section
// 4.7.1) allows a float x / y 2.5 ulp of error and sqrt(x) that of
// 1.0 / inversesqrt(x), and vendor drivers use it (reciprocal and reciprocal
// square root approximations). Computed in double and rounded once to float,
// each is the IEEE result the CPU computes: a double carries 53 >= 2 * 24 + 2
// bits, so rounding a quotient or square root twice cannot differ from
// rounding it once. Infinities, signed zeros and NaNs come out as in float.
float div_rn(float a, float b) {
  precise double q = double(a) / double(b);
  return float(q);
}
float sqrt_rn(float a) {
  precise double r = sqrt(double(a));
  return float(r);
}

void make_primary_ray(int x, int y) {
  // primary_ray: pixel centre in [0, 1]^2.
  precise float u = div_rn(float(x) + 0.5, float(u_width));
  precise float v = div_rn(float(y) + 0.5, float(u_height));
  // camera_ray: sx = (2u - 1) * tan_half * aspect, sy = (1 - 2v) * tan_half.
  precise float sx = ((2.0 * u - 1.0) * u_tan_half) * u_aspect;
  precise float sy = (1.0 - 2.0 * v) * u_tan_half;
  // glm: forward + sx * right + sy * up, left to right, per component.
  precise vec3 d = vec3((u_forward.x + sx * u_right.x) + sy * u_up.x, (u_forward.y + sx * u_right.y) + sy * u_up.y,
                        (u_forward.z + sx * u_right.z) + sy * u_up.z);
  // glm::normalize: d * (1 / sqrt(dot(d, d))), dot = (x*x + y*y) + z*z.
  precise float dd = (d.x * d.x + d.y * d.y) + d.z * d.z;
  precise float s = sqrt_rn(dd);
  precise float rs = div_rn(1.0, s);
  precise vec3 dir = vec3(d.x * rs, d.y * rs, d.z * rs);
  g_origin = u_position;
  g_dir = dir;
  precise vec3 inv = vec3(div_rn(1.0, dir.x), div_rn(1.0, dir.y), div_rn(1.0, dir.z));
  g_inv = inv;
  g_tmin = 0.0;
  g_tmax = inf_f();
}

void make_watertight_ray() {
  vec3 a = abs(g_dir);
  g_kz = (a.x > a.y) ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  g_kx = (g_kz + 1) % 3;
  g_ky = (g_kx + 1) % 3;
  if (g_dir[g_kz] < 0.0) {
    int t = g_kx;
    g_kx = g_ky;
    g_ky = t;
  }
  precise float sx = div_rn(g_dir[g_kx], g_dir[g_kz]);
  precise float sy = div_rn(g_dir[g_ky], g_dir[g_kz]);
  precise float sz = div_rn(1.0, g_dir[g_kz]);
  g_sx = sx;
  g_sy = sy;
  g_sz = sz;
}

// ---- slab test (core/math/aabb.h intersect_slab, padded) ----------------------

bool slab(uint i, float tmin, float tmax, out float t_entry, out float t_exit) {
  Node n = nodes[i];
  vec3 lo = vec3(n.lo_x, n.lo_y, n.lo_z);
  vec3 hi = vec3(n.hi_x, n.hi_y, n.hi_z);
  precise float t0 = tmin;
  precise float t1 = tmax;
  for (int a = 0; a < 3; ++a) {
    bool neg = g_inv[a] < 0.0;
    float near_plane = neg ? hi[a] : lo[a];
    float far_plane = neg ? lo[a] : hi[a];
    precise float tn = (near_plane - g_origin[a]) * g_inv[a];
    precise float tf = ((far_plane - g_origin[a]) * g_inv[a]) * u_slab_scale;
    t0 = tn > t0 ? tn : t0;  // NaN: comparison false, t0 kept
    t1 = tf < t1 ? tf : t1;  // NaN: comparison false, t1 kept
  }
  t_entry = t0;
  t_exit = t1;
  return t0 <= t1;
}

// ---- triangle tests (core/geometry/triangle.cpp) -------------------------------

// intersect_watertight_double
bool watertight_double(uint k, float tmin, float tmax, out float t_out) {
  dvec3 o = dvec3(g_origin), d = dvec3(g_dir);
  precise double sx = d[g_kx] / d[g_kz];
  precise double sy = d[g_ky] / d[g_kz];
  precise double sz = 1.0LF / d[g_kz];
  precise dvec3 A = dvec3(vert(k, 0)) - o;
  precise dvec3 B = dvec3(vert(k, 1)) - o;
  precise dvec3 C = dvec3(vert(k, 2)) - o;
  precise double ax = A[g_kx] - sx * A[g_kz], ay = A[g_ky] - sy * A[g_kz];
  precise double bx = B[g_kx] - sx * B[g_kz], by = B[g_ky] - sy * B[g_kz];
  precise double cx = C[g_kx] - sx * C[g_kz], cy = C[g_ky] - sy * C[g_kz];
  precise double U = cx * by - cy * bx;
  precise double V = ax * cy - ay * cx;
  precise double W = bx * ay - by * ax;
  if ((U < 0.0LF || V < 0.0LF || W < 0.0LF) && (U > 0.0LF || V > 0.0LF || W > 0.0LF)) return false;
  precise double det = (U + V) + W;
  if (det == 0.0LF || !finite_d(det)) return false;
  precise double T = (U * (sz * A[g_kz]) + V * (sz * B[g_kz])) + W * (sz * C[g_kz]);
  precise double t = T / det;
  if (!(t >= double(tmin) && t <= double(tmax))) return false;
  float tf = float(t);
  if (!(tf >= tmin && tf <= tmax)) tf = t < double(tmin) ? tmin : tmax;
  t_out = tf;
  return true;
}

// watertight_sheared_double: steps 6 and 7 in double on the float-sheared coordinates, so that a
// shared edge is decided as the neighbour's float test decides it (the fresh double shear above did
// not: holes at tiny hit distances).
bool watertight_sheared_double(float ax, float ay, float bx, float by, float cx, float cy, float az, float bz,
                               float cz, float tmin, float tmax, out float t_out) {
  precise double U = double(cx) * double(by) - double(cy) * double(bx);
  precise double V = double(ax) * double(cy) - double(ay) * double(cx);
  precise double W = double(bx) * double(ay) - double(by) * double(ax);
  if ((U < 0.0LF || V < 0.0LF || W < 0.0LF) && (U > 0.0LF || V > 0.0LF || W > 0.0LF)) return false;
  precise double det = (U + V) + W;
  if (det == 0.0LF || !finite_d(det)) return false;
  precise double T = (U * double(az) + V * double(bz)) + W * double(cz);
  precise double t = T / det;
  if (!(t >= double(tmin) && t <= double(tmax))) return false;
  float tf = float(t);
  if (!(tf >= tmin && tf <= tmax)) tf = t < double(tmin) ? tmin : tmax;
  t_out = tf;
  return true;
}

// intersect_watertight (the inline twin in the BVH gives the same results)
bool watertight(uint k, float tmin, float tmax, out float t_out) {
  precise vec3 A = vert(k, 0) - g_origin;
  precise vec3 B = vert(k, 1) - g_origin;
  precise vec3 C = vert(k, 2) - g_origin;
  precise float ax = A[g_kx] - g_sx * A[g_kz];
  precise float ay = A[g_ky] - g_sy * A[g_kz];
  precise float bx = B[g_kx] - g_sx * B[g_kz];
  precise float by = B[g_ky] - g_sy * B[g_kz];
  precise float cx = C[g_kx] - g_sx * C[g_kz];
  precise float cy = C[g_ky] - g_sy * C[g_kz];
  precise float U = cx * by - cy * bx;
  precise float V = ax * cy - ay * cx;
  precise float W = bx * ay - by * ax;
  precise float az = g_sz * A[g_kz];
  precise float bz = g_sz * B[g_kz];
  precise float cz = g_sz * C[g_kz];
  precise float sum = (U + V) + W;
  if (!finite_f(sum)) {
    if (finite_f(ax) && finite_f(ay) && finite_f(bx) && finite_f(by) && finite_f(cx) && finite_f(cy) && finite_f(az) &&
        finite_f(bz) && finite_f(cz))
      return watertight_sheared_double(ax, ay, bx, by, cx, cy, az, bz, cz, tmin, tmax, t_out);
    return watertight_double(k, tmin, tmax, t_out);
  }
  if (U == 0.0 || V == 0.0 || W == 0.0) {
    // Products of floats are exact in double; one rounding to double, one to float.
    precise double dU = double(cx) * double(by) - double(cy) * double(bx);
    precise double dV = double(ax) * double(cy) - double(ay) * double(cx);
    precise double dW = double(bx) * double(ay) - double(by) * double(ax);
    U = float(dU);
    V = float(dV);
    W = float(dW);
    // Below about 1e-22 the products underflow float altogether: the whole test in double.
    if ((U == 0.0 && dU != 0.0LF) || (V == 0.0 && dV != 0.0LF) || (W == 0.0 && dW != 0.0LF))
      return watertight_sheared_double(ax, ay, bx, by, cx, cy, az, bz, cz, tmin, tmax, t_out);
  }
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  precise float det = (U + V) + W;
  if (det == 0.0) return false;
  if (abs(det) < kWatertightLowRange)
    return watertight_sheared_double(ax, ay, bx, by, cx, cy, az, bz, cz, tmin, tmax, t_out);
  precise float T = (U * az + V * bz) + W * cz;
  if (!finite_f(T) || (abs(T) < kWatertightLowRange && T != 0.0)) {
    if (finite_f(az) && finite_f(bz) && finite_f(cz))
      return watertight_sheared_double(ax, ay, bx, by, cx, cy, az, bz, cz, tmin, tmax, t_out);
    return watertight_double(k, tmin, tmax, t_out);
  }
  // watertight_accept
  precise float lo_s = tmin * det;
  precise float hi_s = tmax * det;
  if (det > 0.0) {
    if (T < lo_s || T > hi_s) return false;
  } else {
    if (T > lo_s || T < hi_s) return false;
  }
  precise float rcp = div_rn(1.0, det);
  precise float t = T * rcp;
  if (!(t >= tmin && t <= tmax)) return false;
  t_out = t;
  return true;
}

// intersect_moller_trumbore; glm's cross and dot written out in their order.
bool moller_trumbore(uint k, float tmin, float tmax, out float t_out) {
  vec3 v0 = vert(k, 0), v1 = vert(k, 1), v2 = vert(k, 2);
  precise vec3 e1 = v1 - v0;
  precise vec3 e2 = v2 - v0;
  vec3 d = g_dir;
  precise vec3 p = vec3(d.y * e2.z - e2.y * d.z, d.z * e2.x - e2.z * d.x, d.x * e2.y - e2.x * d.y);
  precise float det = (e1.x * p.x + e1.y * p.y) + e1.z * p.z;
  if (det == 0.0) return false;
  precise float inv = div_rn(1.0, det);
  precise vec3 s = g_origin - v0;
  precise float u = ((s.x * p.x + s.y * p.y) + s.z * p.z) * inv;
  if (u < 0.0 || u > 1.0) return false;
  precise vec3 q = vec3(s.y * e1.z - e1.y * s.z, s.z * e1.x - e1.z * s.x, s.x * e1.y - e1.x * s.y);
  precise float v = ((d.x * q.x + d.y * q.y) + d.z * q.z) * inv;
  precise float uv = u + v;
  if (v < 0.0 || uv > 1.0) return false;
  precise float t = ((e2.x * q.x + e2.y * q.y) + e2.z * q.z) * inv;
  if (!(t >= tmin && t <= tmax)) return false;
  t_out = t;
  return true;
}

bool test_triangle(uint k, float tmin, float tmax, out float t_out) {
  return u_watertight != 0 ? watertight(k, tmin, tmax, t_out) : moller_trumbore(k, tmin, tmax, t_out);
}

// ---- traversal -------------------------------------------------------------------

void main() {
  int px = int(gl_GlobalInvocationID.x), py = u_row0 + int(gl_GlobalInvocationID.y);
  if (px >= u_width || py >= u_row_end || py >= u_height) return;
  make_primary_ray(px, py);

  uint visited = 0u, box_tests = 0u, prim_tests = 0u, culled = 0u, missed = 0u;
  uint best_prim = kInvalid;
  float best_t = inf_f();
  float closest = g_tmax;
  float tmin = g_tmin;
  bool xray = u_xray != 0;

  uint stack_node[kMaxDepth];
  float stack_t[kMaxDepth];
  int sp = 0;

  bool done = u_node_count == 0u;
  if (!done) {
    float r0, r1;
    ++box_tests;
    if (!slab(0u, tmin, closest, r0, r1)) {
      ++missed;
      done = true;
    } else {
      ++visited;
    }
  }
  if (!done && u_watertight != 0) make_watertight_ray();

  uint node = 0u;
  while (!done) {
    Node n = nodes[node];
    bool descended = false;
    if (n.count == 0u) {
      uint i0 = n.index, i1 = n.index + 1u;
      float a0, a1, b0, b1;
      bool h0 = slab(i0, tmin, g_tmax, a0, a1);
      bool h1 = slab(i1, tmin, g_tmax, b0, b1);
      box_tests += 2u;
      float cull_t = xray ? g_tmax : closest;
      if (!h0) ++missed;
      else if (a0 > cull_t) { ++culled; h0 = false; }
      if (!h1) ++missed;
      else if (b0 > cull_t) { ++culled; h1 = false; }
      if (h0 && h1) {
        bool second_first = u_ordered != 0 && (u_back_to_front != 0 ? a0 < b0 : b0 < a0);
        uint near_child = i0 + (second_first ? 1u : 0u);
        uint far_child = i1 - (second_first ? 1u : 0u);
        stack_node[sp] = far_child;
        stack_t[sp] = second_first ? a0 : b0;
        ++sp;
        node = near_child;
        ++visited;
        descended = true;
      } else if (h0 || h1) {
        node = i0 + (h1 ? 1u : 0u);
        ++visited;
        descended = true;
      }
    } else {
      for (uint k = n.index; k < n.index + n.count; ++k) {
        float prim_tmax = xray ? g_tmax : closest;
        float t = 0.0;
        bool hit = test_triangle(k, tmin, prim_tmax, t);
        ++prim_tests;
        if (hit && t < best_t) {  // first found wins ties
          best_t = t;
          best_prim = k;
          closest = t;
        }
      }
    }
    if (descended) continue;
    // Pop the next node whose entry still lies before the closest hit.
    for (;;) {
      if (sp == 0) {
        done = true;
        break;
      }
      --sp;
      if (stack_t[sp] > closest && !xray) {
        ++culled;
        continue;
      }
      node = stack_node[sp];
      ++visited;
      break;
    }
  }

  uint i = uint(py) * uint(u_width) + uint(px);
  pixels[i].nodes_visited = visited;
  pixels[i].box_tests = box_tests;
  pixels[i].prim_tests = prim_tests;
  pixels[i].nodes_culled = culled;
  pixels[i].nodes_missed = missed;
  pixels[i].prim = best_prim;
  pixels[i].t = best_t;
  pixels[i].pad = 0u;
}
