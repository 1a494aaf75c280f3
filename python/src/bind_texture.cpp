// Python bindings of geods::texture: synthesize_texture and fill_hole.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/texture/stats_fields.hpp"
#include "geods/texture/synthesis.hpp"
#include "stats_dict.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

texture::SynthesisOptions synthesis_options(std::size_t neighborhood, std::size_t parent_neighborhood,
                                            std::size_t levels, const std::string& search, double eps,
                                            std::size_t reduced_dimension, std::size_t refinement_passes,
                                            std::uint64_t seed) {
  texture::SynthesisOptions o;
  o.neighborhood = neighborhood;
  o.parent_neighborhood = parent_neighborhood;
  o.levels = levels;
  o.search = texture::parse_neighbor_search(search);
  o.eps = eps;
  o.reduced_dimension = reduced_dimension;
  o.refinement_passes = refinement_passes;
  o.seed = seed;
  return o;
}

/// The image, or (image, stats) when the caller asked for the stats.
py::object texture_result(const texture::SynthesisResult& result, bool stats) {
  py::array_t<std::uint8_t> image = image_array(result.image);
  if (!stats) return image;
  return py::make_tuple(image, stats_dict(result.stats));
}

py::object synthesize_texture_py(const Rows<std::uint8_t>& sample, const std::array<std::size_t, 2>& size,
                                 std::size_t neighborhood, std::size_t parent_neighborhood, std::size_t levels,
                                 const std::string& search, double eps, std::size_t reduced_dimension,
                                 std::size_t refinement_passes, std::uint64_t seed, bool tile, bool stats) {
  texture::TextureRequest request;
  request.width = size[0];
  request.height = size[1];
  request.tile = tile;
  request.options = synthesis_options(neighborhood, parent_neighborhood, levels, search, eps, reduced_dimension,
                                      refinement_passes, seed);
  const Image<std::uint8_t> in = image_from_array(sample, "synthesize_texture");
  return texture_result(without_gil([&] { return texture::synthesize_texture(in, request); }), stats);
}

py::object fill_hole_py(const Rows<std::uint8_t>& image, const Rows<std::uint8_t>& mask,
                        const std::optional<Rows<std::uint8_t>>& sample, std::size_t neighborhood,
                        std::size_t parent_neighborhood, std::size_t levels, const std::string& search, double eps,
                        std::size_t reduced_dimension, std::size_t refinement_passes, std::uint64_t seed,
                        bool stats) {
  const texture::SynthesisOptions options = synthesis_options(neighborhood, parent_neighborhood, levels, search, eps,
                                                              reduced_dimension, refinement_passes, seed);
  const Image<std::uint8_t> im = image_from_array(image, "fill_hole"), m = image_from_array(mask, "fill_hole: mask");
  std::optional<Image<std::uint8_t>> s;
  if (sample) s = image_from_array(*sample, "fill_hole: sample");
  return texture_result(without_gil([&] { return texture::fill_hole(im, m, options, s ? &*s : nullptr); }), stats);
}

}  // namespace

void bind_texture(py::module_& m) {
  const texture::SynthesisOptions d;  // the defaults, stated once in C++
  m.def("synthesize_texture", &synthesize_texture_py, py::arg("sample"), py::arg("size"), py::arg("neighborhood") = d.neighborhood,
        py::arg("parent_neighborhood") = d.parent_neighborhood, py::arg("levels") = d.levels, py::arg("search") = "approx",
        py::arg("eps") = d.eps, py::arg("reduced_dimension") = d.reduced_dimension, py::arg("refinement_passes") = d.refinement_passes,
        py::arg("seed") = d.seed, py::arg("tile") = false, py::arg("stats") = false,
        R"doc(A texture of size (width, height) like `sample` (Wei-Levoy, seed §5.5).

sample: uint8 (h, w) grey or (h, w, c) with 1 to 4 channels; the result has
its channels, shape (height, width[, c]). Each pixel takes the sample pixel
whose neighbourhood (causal neighborhood x neighborhood window, and a
parent_neighborhood window one pyramid level coarser; 0: neighborhood/2
rounded up to odd) is nearest. search: 'approx' ((1 + eps) k-d tree over
reduced_dimension principal components; 0: 8), 'exact' (the same tree,
exact) or 'brute'. levels: pyramid levels (0: from the sample size, at most
4). tile=True: a toroidal output that tiles without seams. The same seed
gives the same bytes on any thread count. stats=True returns (image, stats).
Raises geods.Error for a sample too small for the windows or bad options.)doc");
  m.def("fill_hole", &fill_hole_py, py::arg("image"), py::arg("mask"), py::arg("sample") = py::none(),
        py::arg("neighborhood") = d.neighborhood, py::arg("parent_neighborhood") = d.parent_neighborhood, py::arg("levels") = d.levels,
        py::arg("search") = "approx", py::arg("eps") = d.eps, py::arg("reduced_dimension") = d.reduced_dimension,
        py::arg("refinement_passes") = d.refinement_passes, py::arg("seed") = d.seed, py::arg("stats") = false,
        R"doc(`image` with the pixels where `mask` is nonzero synthesized to match their surroundings.

mask: uint8 (h, w) (or (h, w, c): its first channel) of the image's size.
Every pixel outside the mask is kept. sample: the texture to fill from
(the image's channels); by default the image's own known part (its windows
that do not touch the hole). Other arguments as for synthesize_texture.)doc");
}

}  // namespace geods::python
