// gl::progressive_radiosity's state: its buffers and textures, and the programs of its passes
// (item buffer, visibility, shot, light shot, reduction), compiled from the GLSL texts of
// radiosity_shaders.cpp.
#include "radiosity_state.hpp"

namespace bounce::gl {

progressive_radiosity::state::state(const scene_view& scene, const lightmap_atlas& a, const radiosity_options& o)
    : atlas(a),
      options(o),
      width(std::max<std::uint32_t>(a.width, 1)),
      height(std::max<std::uint32_t>(a.height, 1)),
      sides(o.shooting.two_sided ? 2 : 1),
      radiosity(texel_format::rgba32f, width, std::size_t(height) * sides),
      unshot(texel_format::rgba32f, width, std::size_t(height) * sides),
      intercepted(texel_format::rgba32f, width, std::size_t(height) * sides),
      item_color(texel_format::rgba32f, std::size_t(o.resolution), item_rows(o)),
      item_depth(texel_format::depth32f, std::size_t(o.resolution), item_rows(o)),
      texels(std::size_t(width) * height * sizeof(texel_attributes)),
      nodes(std::size_t(1) * sizeof(gpu_node)),
      planes(std::max<std::size_t>(scene.triangles.size(), 1) * sizeof(glm::vec4)),
      first_buffer((a.size() + 1) * sizeof(std::uint32_t)),
      element_texel(std::max<std::size_t>(a.size(), 1) * sizeof(std::uint32_t)),
      partials(sizeof(double)) {
    const std::size_t n = atlas.size();
    // Two-sided, an emitter emits on the side the reference integrator gives it (its vertex
    // normals' side, emission_sides), as on the CPU; one-sided, on its front.
    if (sides == 2) emits_back = emission_sides(scene, atlas);
    // Element attributes per texel, and the initial radiosity and unshot radiosity E (each
    // side's rows).
    std::vector<glm::vec4> initial(std::size_t(width) * height * sides, glm::vec4(0.f));
    std::vector<std::uint32_t> packed(std::max<std::size_t>(n, 1), 0u);
    glm::dvec3 emitted_surfaces(0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::uvec2 tx = atlas.texel[i];
        const std::size_t at = std::size_t(tx.y) * width + tx.x;
        initial[at + (emits_on(i, 0) ? 0 : std::size_t(width) * height)] = glm::vec4(atlas.emission[i], 0.f);
        packed[i] = tx.x | (tx.y << 16);
        emitted_surfaces += glm::dvec3(atlas.emission[i]) * double(atlas.area[i]);
        total_area += double(atlas.area[i]);
        albedo_area += glm::dvec3(atlas.albedo[i]) * double(atlas.area[i]);
    }
    emitted = emitted_surfaces;
    upload_texel_attributes();
    effective_shot.assign(sides * n, glm::vec3(0.f));
    for (const light& l : scene.lights) lights.push_back(pack(l));
    element_texel.write(0, packed.data(), packed.size() * sizeof(std::uint32_t));
    {
        detail::unpack_state unpack;
        for (const texture* tex : {&radiosity, &unshot})
            glTextureSubImage2D(tex->id(), 0, 0, 0, GLsizei(width), GLsizei(height * sides), GL_RGBA, GL_FLOAT,
                                initial.data());
        const glm::vec4 zero(0.f);
        glClearTexImage(intercepted.id(), 0, GL_RGBA, GL_FLOAT, &zero);
        check_error("uploading the radiosity textures");
    }

    // Shooters: blocks or elements, their centres and texel rectangles.
    first = shooter_ranges(atlas, options.shooting.shoot_blocks);
    const std::size_t shooters = first.size() - 1;
    rect.resize(shooters);
    for (std::size_t k = 0; k < shooters; ++k) {
        glm::uvec2 mn(std::numeric_limits<std::uint32_t>::max()), mx(0u);
        for (std::uint32_t i = first[k]; i < first[k + 1]; ++i) {
            mn = glm::min(mn, atlas.texel[i]);
            mx = glm::max(mx, atlas.texel[i]);
        }
        rect[k] = glm::uvec4(mn, mx - mn + 1u);
    }
    place_shooters();
    std::vector<std::uint32_t> first_padded(first);
    first_buffer = buffer(first_padded.size() * sizeof(std::uint32_t), first_padded.data());
    partials = buffer((shooters * sides + 2) * partial_doubles * sizeof(double));
    // The near-field tree of a block of b x b texels: b^2 + (b/2)^2 + ... nodes at most.
    if (options.shooting.shoot_blocks) {
        int b = atlas.block_texels, count = 0;
        for (;;) {
            count += b * b;
            if (b == 1) break;
            b = (b + 1) / 2;
        }
        max_nodes = count;
        // Depth-first, a stack holds at most 3 siblings waiting per level below the root plus
        // the 4 children just pushed: 3 (levels - 1) + 4 with levels = ceil(log2 b) + 1.
        int levels = 1;
        for (int side = atlas.block_texels; side > 1; side = (side + 1) / 2) ++levels;
        stack_size = 3 * (levels - 1) + 4;
    }
    nodes = buffer(std::size_t(max_nodes) * sizeof(gpu_node));

    place_triangles(scene);
    local_plane.assign(std::max<std::size_t>(corners.size(), 1), glm::vec4(0.f, 0.f, 1.f, 0.f));

    item_fbo.attach_color(0, item_color);
    item_fbo.attach_depth(item_depth);
    item_fbo.set_draw_buffers(1);
    item_fbo.check_complete();
    compile();
}

void progressive_radiosity::state::upload_texel_attributes() {
    std::vector<texel_attributes> attributes(std::size_t(width) * height);
    for (std::size_t i = 0; i < atlas.size(); ++i)
        attributes[std::size_t(atlas.texel[i].y) * width + atlas.texel[i].x] = {
            glm::vec4(atlas.position[i], atlas.area[i]), glm::vec4(atlas.normal[i], float(atlas.chart[i])),
            glm::vec4(atlas.albedo[i], 0.f)};
    texels.write(0, attributes.data(), attributes.size() * sizeof(texel_attributes));
}

void progressive_radiosity::state::place_shooters() {
    centre.resize(first.size() - 1);
    for (std::size_t k = 0; k + 1 < first.size(); ++k) centre[k] = shooter_disc_of(atlas, first[k], first[k + 1]).centre;
}

void progressive_radiosity::state::place_triangles(const scene_view& scene) {
    // Triangles that have a chart (the CPU item buffer's).
    item_triangles triangles = item_buffer_triangles(scene, atlas);
    corners = std::move(triangles.corners);
    triangle_chart = std::move(triangles.chart);
    world_plane = std::move(triangles.world_plane);
    const auto [blo, bhi] = scene.bounds();
    lo = blo;
    hi = bhi;
    diagonal = std::max(glm::length(hi - lo), 1e-30f);
    cube_vertices.reset();  // the hemicube's and directional lights' world vertices, made again when drawn
}

void progressive_radiosity::state::compile() {
    using namespace radiosity_glsl;
    item_program = std::make_unique<program>(item_buffer_vertex(), item_buffer_fragment());
    cube_program = std::make_unique<program>(hemicube_vertex(), hemicube_fragment());
    parallel_program = std::make_unique<program>(parallel_vertex(), parallel_fragment());
    distribute_program = std::make_unique<program>(program::compute(distribute_compute(max_nodes, stack_size)));
    light_program = std::make_unique<program>(program::compute(light_compute()));
    reduce_program = std::make_unique<program>(program::compute(reduce_compute()));
    finish_program = std::make_unique<program>(program::compute(finish_compute()));
    rescale_program = std::make_unique<program>(program::compute(rescale_compute()));
}

}  // namespace bounce::gl
