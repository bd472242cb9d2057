// Writing a whole output folder at once (scene sets, training views): the
// folder is filled under OUT.partial and renamed into place at the end, so an
// interrupted or failed run never leaves OUT looking complete.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace pb {

// Removes a stale OUT.partial, creates it empty and calls fill(OUT.partial);
// then OUT.partial takes the place of `out` (a previous `out` is moved to
// OUT.old and removed; missing parent folders are created). On any error the
// partial folder is removed and the error passed on; a filesystem error
// becomes InputError(out, "--out", error_prefix + its text).
void write_folder_atomically(const std::string& out, const std::string& error_prefix,
                             const std::function<void(const std::filesystem::path& tmp)>& fill);

}  // namespace pb
