// Files the way Ninja needs them (docs/developing.md "Rules", 7; Ninja manual, "restat"):
//  - WriteFileIfChanged: the whole content is prepared in memory first, compared with what is
//    on disk, and only when it differs written to a temporary file in the same folder, flushed
//    (fsync) and renamed over the target. A crash or SIGKILL at any moment leaves either the old
//    file or the new one, never a partial file; an unchanged file keeps its mtime, so Ninja's
//    `restat = 1` prunes everything downstream.
//  - One transaction per command: between BeginOutputTransaction() and CommitOutputTransaction()
//    (io/cli.h's ToolCli::Run opens one around every tool's body) WriteFileIfChanged only
//    *stages* a changed file as `<target>.tmp-<pid>` (written and flushed); the commit first
//    writes a journal `.skybake-commit-<pid>` beside the first staged file listing every target,
//    then renames each staged file over its target, then removes the journal. A command that
//    fails (AbortOutputTransaction) removes its staged files and leaves every old output as it
//    was. A run killed while staging leaves only temporary files; one killed during the renames
//    leaves its journal. The next transaction that writes into that folder completes a dead
//    run's journal (renames the staged files it lists that are still there), so the folder holds
//    the complete new set, and removes every other `*.tmp-<pid>` whose process is gone.
//  - Depfiles in Make syntax listing the inputs a tool read (`deps = gcc`).
//  - Content hashes for provenance (xxHash XXH3-64, hex).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace skybake {

// Reads a whole file; throws InputError(path) if it cannot be read.
std::string ReadFileBytes(const std::filesystem::path& path);

// Writes `bytes` to `path` atomically unless the file already holds exactly these bytes.
// Creates missing parent folders. Returns true when the file was (re)written.
// Throws InputError for I/O failures (e.g. an unwritable folder).
bool WriteFileIfChanged(const std::filesystem::path& path, std::string_view bytes);

// The command's output transaction (see the file comment). Begin/Commit/Abort are called by
// ToolCli::Run; a tool that must see its outputs on disk before it ends (skybake bake, before it
// runs ninja) calls CommitOutputTransaction() itself, which also opens a new transaction.
// Without an open transaction WriteFileIfChanged renames at once.
void BeginOutputTransaction();
// Renames every staged file over its target; returns how many files it replaced.
size_t CommitOutputTransaction();
// Removes the staged files and closes the transaction; the old outputs stay untouched.
void AbortOutputTransaction();
// Completes a dead run's journal and removes stale `*.tmp-<pid>` files (pid not running) in
// `dir`. Called for the folder of every file staged; exposed for tests.
void RecoverOutputFolder(const std::filesystem::path& dir);

// Make-syntax depfile "target: in1 in2 ...", written with WriteFileIfChanged.
void WriteDepfile(const std::filesystem::path& depfile, const std::filesystem::path& target,
                  const std::vector<std::filesystem::path>& inputs);

// XXH3-64 of bytes / of a file's content, as 16 lowercase hex digits.
std::string HashBytes(std::string_view bytes);
std::string HashFile(const std::filesystem::path& path);

// Test hooks (tests/cli/test_kill.py): when the environment variable
// SKYBAKE_TEST_SLOW_WRITE_MS is set, WriteFileIfChanged writes its temporary file in small
// chunks with that many milliseconds between them, so a test can kill a tool mid-write.
// SKYBAKE_TEST_SLOW_COMMIT_MS pauses that long after each rename of a commit, so that a kill
// lands between the renames (tests/cli/test_kill.py).

}  // namespace skybake
