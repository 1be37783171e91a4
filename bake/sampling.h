// Deterministic ray directions for integrals over hemispheres and spheres.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace daylit::bake {

// `count` cosine-weighted directions about +Z from a Hammersley point set (stratified: the
// error of a smooth integral falls much faster than 1/sqrt(count)). Averaging f over them
// estimates (1/π) ∫ f(ω) cos θ dω.
std::vector<glm::vec3> CosineHemisphere(int count);

// An orthonormal basis whose third axis is the unit vector `n` (Duff et al. 2017, "Building an
// Orthonormal Basis, Revisited"); columns t, b, n.
glm::mat3 BasisAround(const glm::vec3& n);

// `count` nearly uniform unit directions over the sphere (spherical Fibonacci lattice).
std::vector<glm::vec3> SphericalFibonacci(int count);

// A rotation angle in [0, 2π) from an integer key (hash), to decorrelate the sample patterns of
// neighbouring points (Cranley-Patterson rotation about the normal).
float RotationOf(uint32_t key);

// BasisAround(n) turned about n by RotationOf(key): the frame that carries a CosineHemisphere
// pattern to the point with unit normal `n` and index `key`.
glm::mat3 HemisphereFrame(const glm::vec3& n, uint32_t key);

// Cells of the model's surfaces for gathering light once per patch instead of per point: a
// `size`-metre square of one side of a surface. The key of the cell holding point y, its side
// given by the unit `normal` facing it, hashed onto `seed` (its surface, and whatever else tells
// cells apart), and the cell's centre dropped onto y's plane, where the cell gathers from.
uint64_t SurfaceCellKey(const glm::vec3& y, const glm::vec3& normal, uint64_t seed, float size);
glm::vec3 SurfaceCellOrigin(const glm::vec3& y, const glm::vec3& normal, float size);

}  // namespace daylit::bake
