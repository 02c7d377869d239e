// Help screens and command-line errors (tools/help.hpp).
#include "tools/help.hpp"

#include <algorithm>
#include <memory>
#include <sstream>
#include <vector>

namespace meshstream::tools {
namespace {

// Help lines are wrapped at this width.
constexpr size_t kWidth = 100;

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

std::string after_first_line(const std::string& text) {
    const size_t end = text.find('\n');
    return end == std::string::npos ? std::string() : text.substr(end + 1);
}

// `text` wrapped at kWidth, each line after `indent` spaces (the first line's indent is
// already written by the caller when `first_indented` is false).
std::string wrap(const std::string& text, size_t indent) {
    std::string out, line;
    std::istringstream words(text);
    std::string word;
    auto flush = [&] {
        if (line.empty()) return;
        out += std::string(indent, ' ') + line + "\n";
        line.clear();
    };
    while (words >> word) {
        if (!line.empty() && indent + line.size() + 1 + word.size() > kWidth) flush();
        line += (line.empty() ? "" : " ") + word;
    }
    flush();
    return out;
}

bool is_flag(const CLI::Option* opt) { return opt->get_type_size() == 0; }

// "-r, --ratio P": the names, then the value's name without the validators' descriptions
// CLI11 appends after a ':'.
std::string option_label(const CLI::Option* opt) {
    std::string label;
    for (const std::string& s : opt->get_snames()) label += (label.empty() ? "-" : ", -") + s;
    for (const std::string& l : opt->get_lnames()) label += (label.empty() ? "--" : ", --") + l;
    if (!is_flag(opt)) {
        const std::string type = opt->get_type_name();
        label += " " + type.substr(0, type.find(':'));
    }
    return label;
}

struct Line {
    std::string label, description;
};

// Option lines, the labels in one column.
std::string option_lines(const std::vector<Line>& lines, bool full) {
    size_t column = 0;
    for (const Line& l : lines) column = std::max(column, l.label.size());
    column = std::min<size_t>(column, 24) + 4;
    std::string out;
    for (const Line& l : lines) {
        std::string head = "  " + l.label;
        head += head.size() < column ? std::string(column - head.size(), ' ') : std::string("  ");
        out += head + first_line(l.description) + "\n";
        if (full) out += wrap(after_first_line(l.description), column);
    }
    return out;
}

// The options of `app` that its help lists, in order: its own, then its parent's (-q, which
// works after the command too), but not the parent's help and version flags.
std::vector<const CLI::Option*> listed_options(const CLI::App* app) {
    std::vector<const CLI::Option*> out =
        app->get_options([](const CLI::Option* o) { return o->nonpositional() && !o->get_group().empty(); });
    if (const CLI::App* parent = app->get_parent())
        for (const CLI::Option* o : parent->get_options()) {
            const bool own = o == parent->get_help_ptr() || o == parent->get_help_all_ptr() ||
                             o == parent->get_version_ptr() || !o->nonpositional() || o->get_group().empty();
            if (!own) out.push_back(o);
        }
    // -h/--help and --help-all last: they are the same for every command.
    std::stable_partition(out.begin(), out.end(), [app](const CLI::Option* o) {
        return o != app->get_help_ptr() && o != app->get_help_all_ptr();
    });
    return out;
}

std::string usage(const CLI::App* app, const std::string& name) {
    std::string line = "Usage: " + name + " [OPTIONS]";
    for (const CLI::Option* p : app->get_options([](const CLI::Option* o) { return o->get_positional(); })) {
        const std::string pname = p->get_name(true);
        line += p->get_required() ? " " + pname : " [" + pname + "]";
    }
    return line + "\n";
}

// The help of a command (a subcommand, or a program without subcommands).
std::string command_help(const CLI::App* app, const std::string& name, bool full) {
    std::string out = name + ": " + first_line(app->get_description()) + "\n" + usage(app, name);
    const std::string more_text = after_first_line(app->get_description());
    if (!more_text.empty()) out += more_text + (more_text.back() == '\n' ? "" : "\n");
    const std::vector<const CLI::Option*> options = listed_options(app);
    std::vector<std::string> groups{"Options"};
    for (const CLI::Option* o : options)
        if (std::find(groups.begin(), groups.end(), o->get_group()) == groups.end()) groups.push_back(o->get_group());
    std::vector<std::string> hidden;
    for (const std::string& group : groups) {
        std::vector<Line> lines;
        for (const CLI::Option* o : options) {
            if (o->get_group() != group) continue;
            if (group != "Options" && !full) {
                hidden.push_back(o->get_lnames().empty() ? "-" + o->get_snames().front()
                                                         : "--" + o->get_lnames().front());
                continue;
            }
            std::string description = o->get_description();
            if (o == app->get_help_ptr() && !full && app->get_help_all_ptr() != nullptr)
                description = first_line(description) + "; --help-all: every option";
            if (o == app->get_help_all_ptr() && !full) continue;
            lines.push_back({option_label(o), description});
        }
        if (!lines.empty()) out += "\n" + group + ":\n" + option_lines(lines, full);
    }
    if (!app->get_footer().empty()) out += "\nExample:\n" + app->get_footer() + "\n";
    if (!hidden.empty()) {
        std::string list;
        for (const std::string& h : hidden) list += (list.empty() ? "" : ", ") + h;
        out += "\nMore options (" + name + " --help-all): " + list + "\n";
        // Wrapped as one paragraph, the first line included.
        const size_t at = out.rfind("\nMore options");
        out = out.substr(0, at + 1) + wrap(out.substr(at + 1), 0);
    }
    return out;
}

// The help of a program with subcommands: the commands, one line each, and the global options.
std::string program_help(const CLI::App* app, const std::string& name, bool full) {
    std::string out = name + ": " + first_line(app->get_description()) + "\n";
    out += "Usage: " + name + " [-q] COMMAND [OPTIONS] ARGS...\n";
    const std::vector<const CLI::App*> commands =
        app->get_subcommands([](const CLI::App* sub) { return !sub->get_name().empty(); });
    size_t column = 0;
    for (const CLI::App* c : commands) column = std::max(column, c->get_name().size());
    out += "\nCommands:\n";
    for (const CLI::App* c : commands)
        out += "  " + c->get_name() + std::string(column + 2 - c->get_name().size(), ' ') +
               first_line(c->get_description()) + "\n";
    std::vector<Line> lines;
    for (const CLI::Option* o : app->get_options([](const CLI::Option* o) { return !o->get_group().empty(); }))
        lines.push_back({option_label(o), o->get_description()});
    out += "\nOptions:\n" + option_lines(lines, full);
    if (!app->get_footer().empty()) out += "\nExample:\n" + app->get_footer() + "\n";
    if (full)
        for (const CLI::App* c : commands) out += "\n\n" + command_help(c, name + " " + c->get_name(), true);
    return out;
}

}  // namespace

std::string HelpFormatter::make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const {
    const bool full = mode == CLI::AppFormatMode::All;
    const bool has_commands =
        !app->get_subcommands([](const CLI::App* sub) { return !sub->get_name().empty(); }).empty();
    return has_commands ? program_help(app, name, full) : command_help(app, name, full);
}

void use_help_formatter(CLI::App& app) {
    app.formatter(std::make_shared<HelpFormatter>());
    app.set_help_flag("-h,--help", "print this help");
    app.set_help_all_flag("--help-all", "print the help with every option");
}

std::string first_unknown_option(const CLI::App& app, const std::string& command, int argc, const char* const* argv) {
    const CLI::App* sub = nullptr;
    if (!command.empty()) {
        const auto found = app.get_subcommands([&command](const CLI::App* s) { return s->get_name() == command; });
        if (!found.empty()) sub = found.front();
    }
    auto find = [&](const std::string& name) -> const CLI::Option* {
        if (sub != nullptr)
            if (const CLI::Option* o = sub->get_option_no_throw(name)) return o;
        return app.get_option_no_throw(name);
    };
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg == "--") break;
        if (arg.size() < 2 || arg[0] != '-') continue;
        // "--name=value", "--name", "-r0.1", "-r"
        const bool long_name = arg[1] == '-';
        const std::string name(long_name ? arg.substr(0, arg.find('=')) : arg.substr(0, 2));
        const CLI::Option* o = find(name);
        if (o == nullptr) return name;
        const bool value_attached = long_name ? arg.find('=') != std::string_view::npos : arg.size() > 2;
        if (!is_flag(o) && !value_attached) ++i;  // its value, which may start with '-'
    }
    return {};
}

std::string parse_error_line(const CLI::App& app, const CLI::ParseError& error, const std::string& program,
                             const std::string& command) {
    std::string what = error.what();
    if (dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr) {
        // "The following argument(s) was (were) not expected: ARG ...": named one at a time.
        std::vector<std::string> extras = app.remaining(true);
        if (const size_t at = what.find("expected: "); extras.empty() && at != std::string::npos) {
            std::istringstream args(what.substr(at + 10));
            for (std::string arg; args >> arg;) extras.push_back(arg);
        }
        if (!extras.empty()) {
            const std::string& arg = extras.front();
            what = arg.size() > 1 && arg[0] == '-' ? "unknown option " + arg.substr(0, arg.find('='))
                                                   : "unexpected argument '" + arg + "'";
        }
    } else if (dynamic_cast<const CLI::ExcludesError*>(&error) != nullptr &&
               what.find(" excludes ") != std::string::npos) {
        const size_t at = what.find(" excludes ");
        what = what.substr(0, at) + " and " + what.substr(at + 10) + " cannot be given together";
    } else if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) != nullptr &&
               what.find(" required ") != std::string::npos && what.ends_with(" missing")) {
        what = what.substr(0, what.find(':')) + " needs a value";  // "--ratio: 1 required P missing"
    }
    return usage_error_line(program, command, what);
}

std::string usage_error_line(const std::string& program, const std::string& command, const std::string& what) {
    const std::string scope = command.empty() ? program : program + " " + command;
    return (command.empty() ? program : program + ": " + command) + ": " + what + "; see " + scope + " --help";
}

}  // namespace meshstream::tools
