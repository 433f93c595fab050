// Files the way Ninja needs them (docs/developing.md "Rules", 7; Ninja manual, "restat"):
//  - WriteFileIfChanged: the whole content is prepared in memory first, compared with what is
//    on disk, and only when it differs written to a temporary file in the same folder, flushed
//    (fsync) and renamed over the target. A crash or SIGKILL at any moment leaves either the old
//    file or the new one, never a partial file; an unchanged file keeps its mtime, so Ninja's
//    `restat = 1` prunes everything downstream.
//  - One transaction per command (docs/pipeline.md, "One transaction per command", states
//    what a reader may observe): between BeginOutputTransaction() and CommitOutputTransaction() (io/cli.h's
//    ToolCli::Run opens one around every tool's body) WriteFileIfChanged only *stages* a
//    changed file as `<target>.tmp-<pid>` (written and flushed). A commit of more than one file
//    writes a journal listing every target into every folder of the set: first as a pending
//    copy `.skybake-commit-<pid>.tmp-<pid>` (locked with flock, written, flushed) in each
//    folder, then each is renamed to `.skybake-commit-<pid>` - the first of these renames is
//    the commit point - then the folders are flushed, then every staged file is renamed over
//    its target with no other I/O between the renames, then the folders are flushed and the
//    journals removed; the lock is held until then. A command that fails
//    (AbortOutputTransaction) removes its staged files and leaves every old output as it was.
//  - Readers honour the journal: ReadFileBytes (which every loader of the core uses) first
//    completes any committed journal in the folder of the file it reads
//    (CompleteCommittedJournals): it waits on a live commit's lock, and rolls a dead run's journal forward. So a skybake tool
//    never reads a mixed set. A run killed while staging leaves only temporary files; one
//    killed after the commit point leaves its journal until the next reader or writer of that
//    folder (or `skybake bake`, which recovers the whole outputs tree before it runs ninja)
//    completes it. Every transaction that writes into a folder also removes the temporary
//    files of dead runs that no journal protects.
//  - Depfiles in Make syntax listing the inputs a tool read (`deps = gcc`).
//  - Content hashes for provenance (xxHash XXH3-64, hex).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace skybake {

// Reads a whole file, after completing the committed journals of its folder (so a set of
// outputs is read complete: the old set or the new one); throws InputError(path) if it cannot
// be read.
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
// Completes the committed journals in `dir`: waits for a live commit to end, rolls a dead
// run's forward. Called by ReadFileBytes for the folder of every file it reads.
void CompleteCommittedJournals(const std::filesystem::path& dir);
// Completes the journals in `dir` and removes the temporary files of dead runs (pid not
// running) that no journal protects, and their uncommitted pending journals. Called for the
// folder of every file staged; exposed for tests.
void RecoverOutputFolder(const std::filesystem::path& dir);
// RecoverOutputFolder for `root` and every folder below it, all journals first (skybake bake
// calls it for the outputs folder before it runs ninja).
void RecoverOutputTree(const std::filesystem::path& root);

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
