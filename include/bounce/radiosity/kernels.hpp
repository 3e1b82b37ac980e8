#pragma once
/// \file radiosity/kernels.hpp
/// Kernels of progressive refinement radiosity on textures (Coombe and Harris 2005, GPU Gems 2
/// ch. 39): the oriented-disc form factor and the radiosity a shot adds to a
/// receiver (its Listing 39-4), the hemispherical (stereographic) projection of the visibility
/// pass (its Listing 39-2) with its inverse and separate depth, and the hemicube's
/// direction -> face and texel map (Cohen and Greenberg 1985), so a GL backend can use either.
///
/// Radiometric convention (derivation: docs/radiosity.md). Every element i carries a radiosity
/// B_i and an unshot radiosity dB_i, both in W/m^2 per channel (what the chapter calls the
/// "energy" in its radiosity and residual textures); its power is B_i A_i (W). An emitting
/// Lambertian surface of radiance L_e has emitted radiosity E = pi L_e. The form factor
/// F_{r->s} from a receiver's differential area to the shooter's disc of area A_s is
/// dimensionless (Wallace, Elmquist and Haines 1989, Eq. 4):
///   F_{r->s} = A_s max(cos_r, 0) max(cos_s, 0) / (pi d^2 + A_s),
/// and a shot from s raises the receiver's radiosity (and unshot radiosity) by
///   dB_r = rho_r dB_s F_{r->s} V(r, s),
/// the gathering form of Cohen et al. 1988's shot dB_r = rho_r dB_s F_{s->r} A_s / A_r
/// (reciprocity A_s F_{s->r} = A_r F_{r->s}). This is the chapter's
/// delta = ShootEnergy * RecvColor * ShootDArea * Fij with Fij = cos cos / (pi d^2 + A_s).
/// The power the receiver intercepts is dB_s F_{r->s} A_r (W), of which rho_r is reflected.
///
/// Two slips of Listing 39-4, fixed here: it clamps the product max(cos_i cos_j, 0), which
/// lets a receiver facing away from a shooter that also faces away gain energy (both cosines
/// negative); each cosine is clamped on its own instead. It also names the shooter's energy
/// ShootEnergy in its parameters and ShooterEnergy in its body.
///
/// Shooter frame: the unit normal n of the shooter is the local +z axis, and the tangents
/// (t, b) are orthonormal_basis(n) (sampling.hpp), so the CPU raster and a GLSL lookup build
/// the same frame from the same normal.

#include <bounce/concepts.hpp>
#include <bounce/vocabulary.hpp>

#include <array>
#include <limits>
#include <numbers>
#include <utility>

namespace bounce::inline radiosity {

// ---------------------------------------------------------------------------------------
// Form factor and shot

/// Form factor F_{r->s} (dimensionless) from a receiving element of area `receiver_area`
/// (m^2, >= 0), taken at its centre `receiver_position` with unit normal `receiver_normal`, to
/// a shooting disc centred at `shooter_position` with unit normal `shooter_normal` and area
/// `shooter_area` (m^2, > 0): Wallace et al. 1989 Eq. 4 with the larger of the two areas in
/// the denominator,
///   F_{r->s} = A_s max(cos_r, 0) max(cos_s, 0) / (pi d^2 + max(A_s, A_r)),
/// so that both directions stay below 1: F_{r->s} < 1, and by reciprocity the fraction of the
/// shooter's power the receiver takes, F_{s->r} = A_r F_{r->s} / A_s, is the disc factor with
/// the two swapped (exact on the axis of a receiving disc seen from a small shooter). The
/// receiver's point alone (receiver_area 0, disc_form_factor) hands a receiver much larger
/// than its distance to a small shooter A_r / A_s times the shooter's power: on the conference
/// room a 4.2 m^2 element half a metre from a 0.13 m^2 one took 4.75 times the shot (issue 30's
/// divergence). Each cosine is clamped separately; coincident points give 0.
template <real T, vec3_of<T> V>
T element_form_factor(const V& receiver_position, const V& receiver_normal, T receiver_area, const V& shooter_position,
                      const V& shooter_normal, T shooter_area) {
    const V r = shooter_position - receiver_position;
    const T d2 = dot(r, r);
    const auto apart = d2 > T(0);
    const T safe_d2 = select(apart, d2, T(1));
    const T inv_d = inversesqrt(safe_d2);
    const T cos_r = max(T(0), dot(receiver_normal, r) * inv_d);
    const T cos_s = max(T(0), -dot(shooter_normal, r) * inv_d);
    const T f = shooter_area * cos_r * cos_s / (T(std::numbers::pi) * safe_d2 + max(shooter_area, receiver_area));
    return select(apart, f, T(0));
}

/// Oriented-disc form factor F_{r->s} (dimensionless, in [0, 1)) from a receiving point at
/// `receiver_position` with unit normal `receiver_normal` to a shooting disc centred at
/// `shooter_position` with unit normal `shooter_normal` and area `shooter_area` (m^2, > 0;
/// typical: one texel, 1e-4 to 1e-2): Wallace et al. 1989 Eq. 4, as in Coombe and Harris
/// Listing 39-4 with each cosine clamped separately. Visibility is not included.
/// The + A_s in the denominator keeps F below 1 as d -> 0 (the exact disc-to-point factor
/// on the axis is A_s / (pi d^2 + A_s)); coincident points give 0. element_form_factor with a
/// receiver of no area; the solvers use element_form_factor.
template <real T, vec3_of<T> V>
T disc_form_factor(const V& receiver_position, const V& receiver_normal, const V& shooter_position,
                   const V& shooter_normal, T shooter_area) {
    return element_form_factor<T, V>(receiver_position, receiver_normal, T(0), shooter_position, shooter_normal,
                                     shooter_area);
}

/// Radiosity (W/m^2 per channel) one shot adds to a receiver: rho_r dB_s F_{r->s} V
/// (Cohen et al. 1988, in the gathering form of Coombe and Harris Listing 39-4).
/// `receiver_albedo`: diffuse reflectance rho_r per channel, in [0, 1];
/// `shooter_unshot`: the shooter's unshot radiosity dB_s (W/m^2 per channel);
/// `visibility`: in [0, 1] (1 seen, 0 hidden; fractions for filtered lookups).
/// The receiver's unshot radiosity grows by the same amount.
template <real T, vec3_of<T> V>
V shot_radiosity(const V& receiver_position, const V& receiver_normal, const V& receiver_albedo,
                 const V& shooter_position, const V& shooter_normal, T shooter_area, const V& shooter_unshot,
                 T visibility) {
    const T f = disc_form_factor<T, V>(receiver_position, receiver_normal, shooter_position, shooter_normal,
                                       shooter_area);
    return receiver_albedo * shooter_unshot * (f * visibility);
}

/// Radiosity shown for an element before convergence: B + rho * ambient (Cohen et al. 1988,
/// section 4.2, the ambient term). `ambient` (W/m^2 per channel) is the interreflection factor
/// 1 / (1 - rho_avg) times the area-weighted mean unshot radiosity, rho_avg the area-weighted
/// mean albedo (both per channel); it vanishes as the solution converges.
template <real T, vec3_of<T> V>
V radiosity_with_ambient(const V& radiosity, const V& albedo, const V& ambient) {
    return radiosity + albedo * ambient;
}

/// radiosity_with_ambient, at least `direct` (the element's radiosity once the lights were
/// shot: emission plus rho times the lights' direct irradiance). After a re-bake dims a light
/// the ambient term is negative (radiosity/rebake.hpp) and the converged indirect light is
/// not: this is the ambient irradiance clamped at minus what the shots delivered,
/// (B - direct) / rho, written without the division (the GL solver, which keeps B and direct,
/// shows it; the CPU solver clamps the ambient at its gathered irradiance).
template <real T, vec3_of<T> V>
V radiosity_with_ambient_at_least_direct(const V& radiosity, const V& albedo, const V& ambient, const V& direct) {
    return max(radiosity_with_ambient<T, V>(radiosity, albedo, ambient), direct);
}

/// Cohen et al. 1988's ambient radiosity (W/m^2 per channel): the unshot power spread over
/// the area the radiosity lives on, times the interreflection factor 1 / (1 - rho_avg)
/// (rho_avg = albedo_area / area, at most 0.999). `area` is one side's total area and
/// `sides` 2 for two-sided elements: each side shows the ambient, so its area counts twice
/// (with one side's area the ambient shown would hold twice the unshot power).
inline glm::dvec3 cohen_ambient(const glm::dvec3& unshot_power, double area, const glm::dvec3& albedo_area, int sides) {
    if (!(area > 0)) return glm::dvec3(0.0);
    const glm::dvec3 rho_avg = glm::min(albedo_area / area, glm::dvec3(0.999));
    return unshot_power / (area * double(sides)) / (glm::dvec3(1.0) - rho_avg);
}

// ---------------------------------------------------------------------------------------
// The shooter's frame and the hemispherical (stereographic) projection

/// Components of `d` along the orthonormal axes `t`, `b`, `n`: (d . t, d . b, d . n). A
/// normal in the shooter's frame, or a point of the shooter's frame in a hemicube face's
/// frame (the axes of hemicube_face_axes).
template <real T, vec3_of<T> V>
V frame_coords(const V& d, const V& t, const V& b, const V& n) {
    return V(dot(d, t), dot(d, b), dot(d, n));
}

/// Coordinates of `p` (world) in the shooter's frame: origin `origin`, axes `t`, `b`, `n`
/// (orthonormal, n the shooter's normal = local +z).
template <real T, vec3_of<T> V>
V to_shooter_frame(const V& p, const V& origin, const V& t, const V& b, const V& n) {
    return frame_coords<T, V>(p - origin, t, b, n);
}

/// A triangle's plane in the shooter's frame (axes `t`, `b`, `n`), as the item-buffer lookups
/// take it (item_plane_beyond): (m, d) with m . x = d and d >= 0, m the triangle's unit
/// `world_normal` in that frame, turned to face away from the shooter; `local_corner` is one
/// of its corners in the shooter's frame. `V4` is constructed from (V, T).
template <real T, vec3_of<T> V, class V4>
V4 shooter_plane(const V& world_normal, const V& local_corner, const V& t, const V& b, const V& n) {
    const V m = frame_coords<T, V>(world_normal, t, b, n);
    const T d = dot(m, local_corner);
    return select(d >= T(0), V4(m, d), V4(-m, -d));
}

/// Stereographic projection of the direction of `local` (shooter frame, non-zero; need not
/// be unit) from the pole (0, 0, -1) onto the plane z = 0: q = w.xy / (1 + w.z), w the unit
/// direction. The upper hemisphere (w.z >= 0) maps onto the unit disc, the horizon onto the
/// unit circle, the normal onto the centre. The projection is conformal and maps great
/// circles to circles or lines, so a triangle's straight edges become arcs and must be
/// tessellated before a rasterizer draws them with straight edges (Coombe and Harris,
/// Figure 39-5). Listing 39-2 of the chapter, which names this projection, in fact keeps
/// w.xy (the orthographic, Nusselt-analogue projection); the stereographic one is used here
/// because it does not crush the horizon: a pixel at the rim spans 2 / res of arc instead of
/// sqrt(2 / res).
template <real T, vec3_of<T> V, vec2_of<T> V2>
V2 stereographic_project(const V& local) {
    const V w = normalize(local);
    const T s = T(1) / (T(1) + w.z);
    return V2(w.x * s, w.y * s);
}

/// Inverse of stereographic_project: the unit direction whose projection is `q`
/// (|q| <= 1 on the upper hemisphere): w = (2 q, 1 - |q|^2) / (1 + |q|^2).
template <real T, vec3_of<T> V, vec2_of<T> V2>
V stereographic_direction(const V2& q) {
    const T r2 = dot(q, q);
    const T s = T(1) / (T(1) + r2);
    return V(T(2) * q.x * s, T(2) * q.y * s, (T(1) - r2) * s);
}

/// Texture coordinates in [0, 1]^2 of the item buffer that stores the stereographic
/// projection (the square [-1, 1]^2 maps to [0, 1]^2; Listing 39-3's proj * 0.5 + 0.5).
template <real T, vec3_of<T> V, vec2_of<T> V2>
V2 stereographic_item_coords(const V& local) {
    const V2 q = stereographic_project<T, V, V2>(local);
    return V2(q.x * T(0.5) + T(0.5), q.y * T(0.5) + T(0.5));
}

/// The unit direction through the point `centre` (texel coordinates; a texel's centre is
/// (x + 1/2, y + 1/2)) of a `res` x `res` stereographic item buffer: stereographic_direction
/// of the inverse of stereographic_item_coords.
template <real T, vec3_of<T> V, vec2_of<T> V2>
V stereographic_texel_direction(const V2& centre, T res) {
    return stereographic_direction<T, V, V2>(V2(centre.x / res * T(2) - T(1), centre.y / res * T(2) - T(1)));
}

/// Depth stored beside the projected position, projected separately as Listing 39-2 does so
/// that depth order is exact whatever the (non-linear) (x, y) projection: the distance from
/// the shooter, mapped from [near, far] (scene units) to [0, 1]. The chapter uses the axial
/// distance -z; the radial distance is used here because it stays well conditioned at the
/// horizon, where the axial distance of every surface tends to 0.
template <real T, vec3_of<T> V>
T hemisphere_depth(const V& local, T near_distance, T far_distance) {
    return (length(local) - near_distance) / (far_distance - near_distance);
}

// ---------------------------------------------------------------------------------------
// Hemicube (Cohen and Greenberg 1985)

/// The hemicube's five faces around the shooter's +z axis. Face f looks along `forward`,
/// with image axes `right` (u) and `up` (v), right x up = forward:
///   top (0): forward +z, right +x, up +y;   +x (1): forward +x, right +y, up +z;
///   -x (2):  forward -x, right -y, up +z;   +y (3): forward +y, right -x, up +z;
///   -y (4):  forward -y, right +x, up +z.
/// The top face is stored as res x res texels over s, t in [-1, 1]; a side face keeps only
/// its upper half (t in [0, 1]) as res x res/2 texels.
enum class hemicube_face : int { top = 0, pos_x = 1, neg_x = 2, pos_y = 3, neg_y = 4 };

/// Face and texture coordinates of the direction of `local` (shooter frame, local.z >= 0):
/// returns (face as a number 0..4, u, v) with u, v in [0, 1] over that face's stored texels
/// (u = (s + 1) / 2; v = (t + 1) / 2 on the top face, v = t on a side face, s and t the
/// perspective coordinates right.w / forward.w and up.w / forward.w). Ties go to the top
/// face, then to the x faces; directions below the horizon land on a side face with v < 0.
/// The faces' axes (right, up, forward) in the shooter's frame, face 0..4 (the table above):
/// frame_coords along them gives a point's coordinates in that face's frame.
template <class V>
std::array<V, 3> hemicube_face_axes(int face) {
    switch (face) {
        case 1: return {V(0, 1, 0), V(0, 0, 1), V(1, 0, 0)};
        case 2: return {V(0, -1, 0), V(0, 0, 1), V(-1, 0, 0)};
        case 3: return {V(-1, 0, 0), V(0, 0, 1), V(0, 1, 0)};
        case 4: return {V(1, 0, 0), V(0, 0, 1), V(0, -1, 0)};
        default: return {V(1, 0, 0), V(0, 1, 0), V(0, 0, 1)};
    }
}

/// (face, u, v) of the point `q` given in the frame of face `face` (0..4 as a number; q's
/// components along the face's right, up and forward axes, q.z > 0): u = (s + 1) / 2, and
/// v = (t + 1) / 2 on the top face, v = t on a side face, with s = q.x / q.z, t = q.y / q.z
/// (hemicube_face_coords on a face already chosen, as a rasterizer of that face needs it).
template <real T, vec3_of<T> V>
V hemicube_coords_on_face(const V& q, T face) {
    const T s = q.x / q.z, t = q.y / q.z;
    const T v = select(face < T(0.5), t * T(0.5) + T(0.5), t);
    return V(face, s * T(0.5) + T(0.5), v);
}

/// Rows of face `face`'s stored texels in a hemicube of `res` texels a side (res even): res
/// on the top face, res / 2 on a side face.
template <real T>
T hemicube_face_rows(T face, T res) {
    return select(face < T(0.5), res, res * T(0.5));
}

/// First row of face `face` where the five faces share one buffer `res` wide and 3 res tall:
/// the top face in rows [0, res), side face f (1..4) from row res + (f - 1) res / 2 on.
template <real T>
T hemicube_face_first_row(T face, T res) {
    return select(face < T(0.5), T(0), res + (face - T(1)) * (res * T(0.5)));
}

/// The clip-space position (V4, constructed from four T) at which a rasterizer drawing face
/// `face` into a viewport over that face's stored texels puts the point `q` (face frame, as
/// hemicube_coords_on_face): divided by w = q.z, its (x, y) are 2 (u, v) - 1 of
/// hemicube_coords_on_face, so the viewport maps it to (u, v) times the face's texels
/// (y = q.y on the top face, 2 q.y - q.z on a side face); z maps the distance along the
/// forward axis from [near_z, far_z] onto [-1, 1] (the perspective depth).
template <real T, vec3_of<T> V, class V4>
V4 hemicube_face_clip(const V& q, T face, T near_z, T far_z) {
    const T y = select(face < T(0.5), q.y, T(2) * q.y - q.z);
    const T a = (far_z + near_z) / (far_z - near_z), b = T(-2) * far_z * near_z / (far_z - near_z);
    return V4(q.x, y, a * q.z + b, q.z);
}

template <real T, vec3_of<T> V>
V hemicube_face_coords(const V& local) {
    const T ax = abs(local.x), ay = abs(local.y);
    const auto top = local.z >= max(ax, ay);
    const auto x_major = ax >= ay;
    const auto x_pos = local.x > T(0), y_pos = local.y > T(0);
    const T side_face = select(x_major, select(x_pos, T(1), T(2)), select(y_pos, T(3), T(4)));
    const T face = select(top, T(0), side_face);
    const T side_major = select(x_major, ax, ay);
    const T major = select(top, local.z, side_major);
    // Numerators of s along each face's right axis (see the table above).
    const T side_s = select(x_major, select(x_pos, local.y, -local.y), select(y_pos, -local.x, local.x));
    const T s_num = select(top, local.x, side_s);
    const T t_num = select(top, local.y, local.z);
    return hemicube_coords_on_face<T, V>(V(s_num, t_num, major), face);
}

/// Inverse of hemicube_face_coords: the direction (not unit; its component along the face's
/// forward axis is 1) through the point (u, v) of face `face` (0..4 as a number).
template <real T, vec3_of<T> V>
V hemicube_direction(T face, T u, T v) {
    const T s = T(2) * u - T(1);
    const auto top = face < T(0.5);
    const T t = select(top, T(2) * v - T(1), v);
    // Components in the shooter frame: forward * 1 + right * s + up * t, per face.
    const T x = select(top, s, select(face < T(1.5), T(1), select(face < T(2.5), T(-1), select(face < T(3.5), -s, s))));
    const T y = select(top, t, select(face < T(1.5), s, select(face < T(2.5), -s, select(face < T(3.5), T(1), T(-1)))));
    const T z = select(top, T(1), t);
    return V(x, y, z);
}

// ---------------------------------------------------------------------------------------
// Item-buffer depth and lookups, and the near-field test: the rules cpu::item_buffer_visibility
// and cpu::progressive_radiosity apply and the GL passes emit as GLSL (docs/radiosity.md,
// sections 3 and 4), written once.

/// Depth (scene units) an item-buffer pixel stores for a surface: the distance from the
/// shooter along the pixel centre's unit direction `w` (shooter frame) to the surface's
/// plane n . x = d (shooter frame, d >= 0), exact at the pixel centre; where the plane is seen
/// edge-on (n . w <= 1e-6) the radial distance `interpolated` across the drawn piece instead.
template <real T, vec3_of<T> V>
T item_plane_depth(const V& plane_normal, T plane_offset, const V& w, T interpolated) {
    const T nw = dot(plane_normal, w);
    const auto facing = nw > T(1e-6);
    return select(facing, plane_offset / select(facing, nw, T(1)), interpolated);
}

/// The plane part of item_buffer_sees (a truth value: bool, or a GLSL boolean): whether the
/// surface a pixel shows, taken as its plane n . x = d (shooter frame, unit n, d >= 0), met
/// along the element's own ray from the shooter, lies beyond the element (shooter frame) less
/// a slack of 1e-4 of the distance plus 1e-6 of the scene's `diagonal`; where that plane is
/// seen edge-on from the element's direction, whether the pixel's stored depth `shown_depth`
/// does.
template <real T, vec3_of<T> V>
auto item_plane_beyond(const V& element, const V& plane_normal, T plane_offset, T shown_depth, T diagonal) {
    const T dist = length(element);
    const T nw = dot(plane_normal, element) / dist;
    const T slack = T(1e-4) * dist + T(1e-6) * diagonal;
    const auto edge_on = nw <= T(1e-6);
    const T met = plane_offset / select(edge_on, T(1), nw);
    return (edge_on && shown_depth >= dist - slack) || (!edge_on && met >= dist - slack);
}

/// Whether an element is seen through its item-buffer pixel (1) or hidden (0): the pixel
/// shows the element's own chart or nothing (`shown_chart` < 0), or item_plane_beyond holds
/// for the surface it shows. The id test alone (Coombe and Harris 2005, Listing 39-3)
/// darkens a row of elements along every concave corner, where the pixel's centre falls on the
/// neighbouring wall at the same depth. `element`: the element's position in the shooter's
/// frame.
template <real T, vec3_of<T> V>
T item_buffer_sees(const V& element, T element_chart, T shown_chart, const V& plane_normal, T plane_offset,
                   T shown_depth, T diagonal) {
    const auto beyond = item_plane_beyond<T, V>(element, plane_normal, plane_offset, shown_depth, diagonal);
    const auto own = shown_chart == element_chart || shown_chart < T(0);
    return select(own || beyond, T(1), T(0));
}

/// The texel (a whole number, as T) in which the buffer coordinate `coord` (texels from the
/// buffer's edge) falls, clamped to the `size` texels of the buffer: an element is looked up
/// at the buffer's border when it projects beyond it (by rounding, at a face's edge).
template <real T>
T item_texel(T coord, T size) {
    return clamp(floor(coord), T(0), size - T(1));
}

/// The texel (x, y) of a `res` x `res` stereographic item buffer at which the element at
/// `local` (shooter frame) is looked up.
template <real T, vec3_of<T> V, vec2_of<T> V2>
V2 stereographic_item_texel(const V& local, T res) {
    const V2 uv = stereographic_item_coords<T, V, V2>(local);
    return V2(item_texel<T>(uv.x * res, res), item_texel<T>(uv.y * res, res));
}

/// (face, x, y): the hemicube face (0..4 as a number) and the texel of that face's stored
/// texels (res wide, hemicube_face_rows tall) at which the element at `local` (shooter
/// frame) is looked up.
template <real T, vec3_of<T> V>
V hemicube_item_texel(const V& local, T res) {
    const V f = hemicube_face_coords<T, V>(local);
    const T rows = hemicube_face_rows<T>(f.x, res);
    return V(f.x, item_texel<T>(f.y * res, res), item_texel<T>(f.z * rows, rows));
}

/// Coordinates (texels) of the world point `p` in a directional light's orthographic buffer:
/// its components across the light (unit axes `t`, `b`) less the buffer's corner `lo`, times
/// `scale` texels per scene unit. Where the buffer's pass draws a corner and where an element
/// is looked up.
template <real T, vec3_of<T> V, vec2_of<T> V2>
V2 parallel_item_coords(const V& p, const V& t, const V& b, const V2& lo, T scale) {
    return (V2(dot(p, t), dot(p, b)) - lo) * scale;
}

/// The square a directional light's `res` x `res` buffer covers across the light (unit axes
/// `t`, `b`): the scene's box [box_lo, box_hi] projected across it, squared about its middle
/// and widened by a texel each side. Returns its corner `lo` (in (t, b) coordinates) and its
/// `scale` in texels per scene unit, as parallel_item_coords takes them; both backends draw
/// and look up the same buffer.
template <real T, vec3_of<T> V, vec2_of<T> V2>
std::pair<V2, T> parallel_item_window(const V& box_lo, const V& box_hi, const V& t, const V& b, T res) {
    T lo_t = std::numeric_limits<T>::max(), lo_b = lo_t, hi_t = -lo_t, hi_b = -lo_t;
    for (int m = 0; m < 8; ++m) {
        const V corner((m & 1) ? box_hi.x : box_lo.x, (m & 2) ? box_hi.y : box_lo.y, (m & 4) ? box_hi.z : box_lo.z);
        const T qt = dot(corner, t), qb = dot(corner, b);
        lo_t = min(lo_t, qt);
        lo_b = min(lo_b, qb);
        hi_t = max(hi_t, qt);
        hi_b = max(hi_b, qb);
    }
    const T side = max(max(hi_t - lo_t, hi_b - lo_b), T(1e-30)) * (T(1) + T(2) / res);
    return {V2(T(0.5) * (lo_t + hi_t) - T(0.5) * side, T(0.5) * (lo_b + hi_b) - T(0.5) * side), res / side};
}

/// The texel (x, y) of a directional light's `res` x `res` buffer at which the element at
/// world position `p` is looked up (parallel_item_coords).
template <real T, vec3_of<T> V, vec2_of<T> V2>
V2 parallel_item_texel(const V& p, const V& t, const V& b, const V2& lo, T scale, T res) {
    const V2 c = parallel_item_coords<T, V, V2>(p, t, b, lo, scale);
    return V2(item_texel<T>(c.x, res), item_texel<T>(c.y, res));
}

/// The plane part of parallel_item_sees (a truth value): for a directional light's
/// orthographic buffer (rays along the unit `direction` the light travels), whether the shown
/// surface's plane (world: unit `plane_normal`, n . x = `plane_offset`) is met downstream of
/// the element at world position `element` along the light (less 1e-6 of the scene's
/// `diagonal`); for a plane parallel to the light, whether the pixel's stored depth along the
/// light `shown_depth` is not upstream of the element's.
template <real T, vec3_of<T> V>
auto parallel_plane_beyond(const V& element, const V& plane_normal, T plane_offset, T shown_depth, const V& direction,
                           T diagonal) {
    const T nd = dot(plane_normal, direction);
    const auto parallel = abs(nd) <= T(1e-6);
    const T s = (plane_offset - dot(plane_normal, element)) / select(parallel, T(1), nd);
    const T slack = T(1e-6) * diagonal;
    return (parallel && shown_depth >= dot(element, direction) - slack) || (!parallel && s >= -slack);
}

/// item_buffer_sees for a directional light's orthographic buffer: the element is seen when
/// its pixel shows its chart or nothing, or when parallel_plane_beyond holds.
template <real T, vec3_of<T> V>
T parallel_item_sees(const V& element, T element_chart, T shown_chart, const V& plane_normal, T plane_offset,
                     T shown_depth, const V& direction, T diagonal) {
    const auto beyond = parallel_plane_beyond<T, V>(element, plane_normal, plane_offset, shown_depth, direction, diagonal);
    const auto own = shown_chart == element_chart || shown_chart < T(0);
    return select(own || beyond, T(1), T(0));
}

/// Whether a receiver at `receiver` sees a node of a block shooter's quadtree (centre
/// `node_position`, area `node_area`) as its children (1) rather than as one disc (0): it lies
/// within sqrt(`near2`) node sides of the node (the near field, a substructuring refinement of
/// Cohen et al. 1986; near2 = near_field^2).
template <real T, vec3_of<T> V>
T near_field_opens(const V& receiver, const V& node_position, T node_area, T near2) {
    const V r = node_position - receiver;
    return select(dot(r, r) < near2 * node_area, T(1), T(0));
}

/// Whether a receiver at `p` lies on the side of a light's hemisphere (apex `position`, unit
/// `axis`) that this hemisphere's shot serves (1) or not (0): dot(p - position, axis) >= 0, or
/// > 0 where `strict` is 1, so that a point light's two opposite hemispheres take a receiver
/// on the plane between them once (the first does).
template <real T, vec3_of<T> V>
T light_hemisphere_side(const V& p, const V& position, const V& axis, T strict) {
    const T z = dot(p - position, axis);
    const auto strictly = strict > T(0.5);
    return select((strictly && z > T(0)) || (!strictly && z >= T(0)), T(1), T(0));
}

}  // namespace bounce::radiosity
