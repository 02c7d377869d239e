// meshstream's API in one header, installed as <meshstream/meshstream.hpp>: whole jobs
// (engine::decimate_file: a file decimated on every core, sorted on demand; engine::convert_file,
// engine::sort_file), the formats
// (io::open_input, io::open_output, io::TriangleInput, io::read_indexed), the stream decimator
// itself (decimate::StreamDecimator), the external sort (sort::ExternalSorter) and the measures
// (compare::compare_meshes, topology and order). Every library throws meshstream::Error's family
// (io/error.hpp). Each header may also be included on its own.
#pragma once

#include "compare/metro.hpp"
#include "compare/order.hpp"
#include "compare/topology.hpp"
#include "decimate/stream_decimator.hpp"
#include "engine/convert.hpp"
#include "engine/decimate.hpp"
#include "engine/files.hpp"
#include "engine/progress.hpp"
#include "engine/warnings.hpp"
#include "io/error.hpp"
#include "io/format.hpp"
#include "io/mesh_index.hpp"
#include "io/read_indexed.hpp"
#include "io/triangle_input.hpp"
#include "sort/external_sort.hpp"
#if MESHSTREAM_WITH_DRACO
#include "io/draco.hpp"
#endif
#if MESHSTREAM_WITH_GLTF
#include "engine/tiles.hpp"
#include "io/gltf.hpp"
#endif
