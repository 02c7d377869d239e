# ctest script: installs the build into a fresh prefix and checks that the headers installed are
# exactly the public ones below. The install takes the API's entry headers and every project
# header they include (MESHSTREAM_PUBLIC_ENTRY_HEADERS), so a public header that includes an
# internal one (the decimator's buffers, queue and quadrics, io's codecs and tables) installs it
# too, and this fails naming it. Variables: BUILD_DIR, WORK_DIR, WITH_DRACO, WITH_GLTF.
set(public
  # What a library user calls, and the types in those calls.
  compare/metro.hpp compare/order.hpp compare/topology.hpp
  decimate/attributes.hpp     # AttributeLayout, AttributeWeights: the decimator's channels
  decimate/emit.hpp           # decimate::Emit: where output chunks go
  decimate/stats.hpp          # decimate::Stats and combine_ranges
  decimate/stream_decimator.hpp
  engine/convert.hpp engine/decimate.hpp engine/files.hpp engine/progress.hpp engine/units.hpp
  engine/tiles.hpp
  engine/warnings.hpp
  engine/part_files.hpp       # PartIndex, part files: a merge's inputs
  engine/ranges.hpp           # RangeProcesses: ranges run by other processes (MPI)
  io/byte_stream.hpp          # ByteSource/ByteSink: what readers read and writers write
  io/chunk.hpp                # TriangleChunk: what flows between the libraries
  io/error.hpp io/format.hpp
  io/input_count.hpp          # a StreamDecimator constructor's argument
  io/mesh_index.hpp
  io/position_key.hpp         # compare::VertexKey
  io/read_indexed.hpp io/triangle_input.hpp
  io/triangle_records.hpp     # the record codec of triangles stored outside a chunk
  meshstream.hpp              # the umbrella
  sort/external_sort.hpp)
if(WITH_DRACO)
  list(APPEND public io/draco.hpp)
endif()
if(WITH_GLTF)
  list(APPEND public io/gltf.hpp)
endif()
list(SORT public)

file(REMOVE_RECURSE "${WORK_DIR}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${rc}):\n${out}\n${err}")
endif()
file(GLOB_RECURSE installed RELATIVE "${WORK_DIR}/prefix/include/meshstream" "${WORK_DIR}/prefix/include/meshstream/*")
list(SORT installed)

set(internal ${installed})
list(REMOVE_ITEM internal ${public})
set(missing ${public})
list(REMOVE_ITEM missing ${installed})
if(internal)
  string(REPLACE ";" " " internal "${internal}")
  message(SEND_ERROR "internal headers installed: ${internal} (a public header includes them: keep them out of "
                     "the public headers, or, when a library user needs one, list it in tests/install/headers.cmake)")
endif()
if(missing)
  string(REPLACE ";" " " missing "${missing}")
  message(SEND_ERROR "public headers not installed: ${missing}")
endif()
if(internal OR missing)
  message(FATAL_ERROR "installed: ${installed}")
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
