// Decimates a file to 10 % on every core through the installed library (README's "Library
// use"): decimate_file IN OUT [THREADS]; prints the input and output triangle counts and the
// ranges decimated at once.
#include <meshstream/meshstream.hpp>

#include <cstdio>
#include <cstdlib>
#include <thread>

int main(int argc, char** argv) {
    if (argc < 3 || argc > 4) {
        std::fprintf(stderr, "usage: decimate_file IN OUT [THREADS]\n");
        return 2;
    }
    namespace engine = meshstream::engine;
    engine::DecimateSettings settings;
    settings.input = argv[1];
    settings.output = argv[2];  // the format from the extension: .ply, .glb, .stl, ...
    settings.ratio = 0.1;
    settings.threads = argc == 4 ? unsigned(std::atoi(argv[3])) : std::thread::hardware_concurrency();
    try {
        engine::QuietProgress progress;  // or a ProgressSink of your own: phases, counts, cancel
        const engine::DecimateResult result = engine::decimate_file(settings, progress);
        for (const engine::Warnings::Line& w : result.warnings.all())
            std::fprintf(stderr, "warning: %s\n", w.text.c_str());
        std::printf("%llu %llu %u\n", (unsigned long long)result.triangles_in,
                    (unsigned long long)result.triangles_out, result.facts.threads);
    } catch (const meshstream::Error& e) {  // io::Error (file and position), io::OptionError
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}
