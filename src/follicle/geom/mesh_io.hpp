#pragma once
// Mesh readers/writers: OBJ (tinyobjloader), PLY (ASCII and binary little/big endian), glTF 2.0
// (.gltf/.glb, tinygltf). The format is chosen by extension. A file's coordinates are in its own
// declared unit; load_mesh converts them to metres, save_mesh converts back.
#include <filesystem>

#include "follicle/core/units.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

/// Reads a mesh. Polygons are cut into triangles along their inside (ear clipping in their
/// plane, up to 64 vertices; larger ones as fans); PLY triangle strips (`tristrips`, -1 between
/// strips) are read too. Throws follicle::Error naming the file (and line
/// where the format has lines) on malformed input: truncation, NaN/Inf, out-of-range indices,
/// empty files, unknown extension.
TriMesh load_mesh(const std::filesystem::path& path, LengthUnit unit);
/// Writes a mesh atomically (temp file + rename). PLY is written binary little-endian unless
/// `ascii` is set.
void save_mesh(const TriMesh& mesh, const std::filesystem::path& path, LengthUnit unit,
               bool ascii = false);

/// Returns a copy whose UVs are per position vertex (uv_faces == faces, uvs.size() ==
/// positions.size()), splitting vertices along UV seams. Formats and GPU buffers that store one
/// attribute set per vertex (PLY, glTF, OpenGL) need this. A mesh without UVs is returned as is.
TriMesh split_uv_seams(const TriMesh& mesh);

}  // namespace follicle::geom
