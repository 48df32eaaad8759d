#include "pnpba/core/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstring>
#include <sstream>

#include "pnpba/core/error.h"

namespace pnpba {

namespace {

std::string osError(const std::string& path, const std::string& what, int error) {
  return path + ": " + what + " (" + std::strerror(error) + ")";
}

std::string folderOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// Follows symbolic links (a dangling one too) to the path that is finally written.
std::string resolveLinks(const std::string& path) {
  std::string current = path;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st;
    if (lstat(current.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return current;
    char target[PATH_MAX];
    const ssize_t n = readlink(current.c_str(), target, sizeof target - 1);
    if (n < 0) throw Error(osError(path, "cannot read symbolic link", errno));
    target[n] = '\0';
    current = target[0] == '/' ? std::string(target) : folderOf(current) + "/" + target;
  }
  throw Error(path + ": too many levels of symbolic links");
}

void writeAll(int fd, const std::string& data, const std::string& path) {
  size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw Error(osError(path, "write failed", errno));
    }
    done += static_cast<size_t>(n);
  }
}

// Devices, FIFOs, sockets: straight in.
void writeInPlace(const std::string& target, const std::string& data, const std::string& path) {
  const int fd = ::open(target.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw Error(osError(path, "cannot open for writing", errno));
  try {
    writeAll(fd, data, path);
  } catch (...) {
    ::close(fd);
    throw;
  }
  if (::close(fd) != 0) throw Error(osError(path, "write failed", errno));
}

// Regular files and new paths: temporary file in the same folder, then rename.
void writeByRename(const std::string& target, const std::string& data, const std::string& path,
                   mode_t mode) {
  const std::string folder = folderOf(target);
  const size_t slash = target.find_last_of('/');
  const std::string name = slash == std::string::npos ? target : target.substr(slash + 1);
  std::string tmp = folder + "/." + name + ".pnpba-XXXXXX";
  const int fd = mkstemp(tmp.data());
  if (fd < 0) throw Error(osError(path, "cannot create a temporary file in " + folder, errno));
  bool open = true;
  try {
    writeAll(fd, data, path);
    if (::fchmod(fd, mode) != 0) throw Error(osError(path, "cannot set permissions", errno));
    if (::fsync(fd) != 0) throw Error(osError(path, "write failed", errno));
    open = false;
    if (::close(fd) != 0) throw Error(osError(path, "write failed", errno));
  } catch (const Error&) {
    if (open) ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  if (::rename(tmp.c_str(), target.c_str()) != 0) {
    const int error = errno;
    ::unlink(tmp.c_str());
    throw Error(osError(path, "cannot replace the file", error));
  }
}

bool sameFile(int fd, const std::string& path) {
  struct stat open_file, named;
  if (fstat(fd, &open_file) != 0 || stat(path.c_str(), &named) != 0) return false;
  return open_file.st_dev == named.st_dev && open_file.st_ino == named.st_ino;
}

}  // namespace

void checkOutputPath(const std::string& path) {
  if (path.empty()) throw Error("output path is empty");
  if (path == "-") return;
  struct stat st;
  // stat follows links the way the kernel does (also /dev/stdout's /proc magic links).
  if (stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw Error(path + ": is a folder, not a file");
    if (!S_ISREG(st.st_mode)) return;  // device, FIFO, socket: written in place
  }
  const std::string target = resolveLinks(path);
  const std::string folder = folderOf(target);
  struct stat dir;
  if (stat(folder.c_str(), &dir) != 0) {
    if (errno == ENOENT) throw Error(path + ": folder does not exist");
    throw Error(osError(path, "folder " + folder, errno));
  }
  if (!S_ISDIR(dir.st_mode)) throw Error(path + ": " + folder + " is not a folder");
  if (access(folder.c_str(), W_OK | X_OK) != 0) {
    throw Error(osError(path, "cannot write in folder " + folder, errno));
  }
}

void writeOutputFile(const std::string& path, const std::function<void(std::ostream&)>& write) {
  std::ostringstream content;
  write(content);
  if (!content) throw Error(path + ": could not produce the content");
  const std::string data = content.str();
  // Our own stdout or stderr (e.g. /dev/stdout while the shell redirects into a file): write
  // into the open descriptor, which keeps appends and pipes intact.
  if (isStandardOutput(path)) {
    writeAll(STDOUT_FILENO, data, path);
    return;
  }
  if (sameFile(STDERR_FILENO, path)) {
    writeAll(STDERR_FILENO, data, path);
    return;
  }
  struct stat st;
  const bool exists = stat(path.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) throw Error(path + ": is a folder, not a file");
  if (exists && !S_ISREG(st.st_mode)) {
    writeInPlace(path, data, path);  // opened through its links, as the kernel resolves them
    return;
  }
  // A regular file or a new path: the file to replace is at the end of any links.
  const std::string target = resolveLinks(path);
  mode_t mode = 0;
  if (exists) {
    mode = st.st_mode & 07777;  // keep the replaced file's permissions
  } else {
    const mode_t mask = umask(0);
    umask(mask);
    mode = 0666 & ~mask;
  }
  writeByRename(target, data, path, mode);
}

bool isStandardOutput(const std::string& path) {
  return path == "-" || sameFile(STDOUT_FILENO, path);
}

bool anyIsStandardOutput(std::initializer_list<std::string> paths) {
  for (const std::string& p : paths) {
    if (!p.empty() && isStandardOutput(p)) return true;
  }
  return false;
}

}  // namespace pnpba
