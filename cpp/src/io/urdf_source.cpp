// SPDX-License-Identifier: BSD-3-Clause
// The URDF reader's stage 0 (urdf_source.hpp): the source read as text, then pre-scanned.
#include "urdf_source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>

#include "armdyn/errors.hpp"
#include "armdyn/io/urdf.hpp"
#include "utf8.hpp"

namespace armdyn::urdf_import {

std::string excerpt(const std::string_view s, size_t max_chars) {
  std::string out;
  size_t shown = 0;
  for (size_t i = 0; i < s.size();) {
    if (shown >= max_chars) {
      out += "...";
      break;
    }
    const size_t n = utf8_sequence(s, i);
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (n == 0 || (n == 1 && (c < 0x20 || c == 0x7F))) {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
      i += 1;
    } else {
      out.append(s.data() + i, n);
      i += n;
    }
    ++shown;
  }
  return out;
}

std::string nm(const std::string& name) { return excerpt(name, 80); }

namespace {

bool looks_like_xml(const std::string& s) {
  // a UTF-8 byte order mark may precede the XML (tinyxml2 skips it)
  const size_t from = s.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  for (size_t i = from; i < s.size(); ++i) {
    const char c = s[i];
    if (std::isspace(static_cast<unsigned char>(c))) continue;
    return c == '<';
  }
  return false;
}

// a path as quoted in messages: its head and its tail when it is long
std::string shown_path(const std::string& path) {
  if (path.size() <= 120) return excerpt(path, 120);
  return excerpt(path.substr(0, 40), 40) + "..." + excerpt(path.substr(path.size() - 60), 60);
}

const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string too_large(const std::string& what, uint64_t bytes) {
  return msg(what, " is ", bytes, " bytes, more than the limit of ", kUrdfMaxBytes, " bytes (",
             kUrdfMaxBytes >> 20, " MiB)");
}

// a source that is not XML must read as a path: not blank, short, one line, no NUL
void check_path_text(const std::string& path) {
  if (path.find_first_not_of(" \t\r\n") == std::string::npos) {
    throw UrdfError("URDF source is empty: expected a file path or URDF XML (starting with '<')");
  }
  if (path.size() > 4096 || path.find('\0') != std::string::npos ||
      path.find('\n') != std::string::npos) {
    throw UrdfError(msg("URDF source is neither XML (it does not start with '<') nor a file path (",
                        path.size(), " bytes): '", excerpt(path), "'"));
  }
}

// the path names a regular file of at most kUrdfMaxBytes (stat: nothing is opened yet)
void stat_regular_file(const std::string& path, const std::string& shown) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ENOENT || err == ENOTDIR) {
      // text with spaces is more likely XML gone wrong than a path
      const bool text = path.find_first_of(" \t") != std::string::npos;
      throw UrdfError(msg("URDF file '", shown, "' not found",
                          text ? " (a URDF string must start with '<')" : ""));
    }
    throw UrdfError(msg("URDF file '", shown, "' cannot be accessed: ", std::strerror(err)));
  }
  if (!S_ISREG(st.st_mode)) {
    throw UrdfError(
        msg("URDF file '", shown, "' is ", file_kind(st.st_mode), ", not a regular file"));
  }
  if (static_cast<uint64_t>(st.st_size) > kUrdfMaxBytes) {
    throw UrdfError(too_large(msg("URDF file '", shown, "'"), static_cast<uint64_t>(st.st_size)));
  }
}

// the file's bytes, read to its end but never past kUrdfMaxBytes (it may grow after the stat)
std::string read_file(const std::string& path, const std::string& shown) {
  // O_NONBLOCK: should the path have been replaced by a FIFO since the stat, open does not wait
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    throw UrdfError(msg("URDF file '", shown, "' cannot be opened: ", std::strerror(errno)));
  }
  struct Close {
    int fd;
    ~Close() { ::close(fd); }
  } close_fd{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    throw UrdfError(msg("URDF file '", shown, "' is not a regular file"));
  }
  std::string text;
  text.reserve(static_cast<size_t>(st.st_size));
  char buf[65536];
  for (;;) {
    const ssize_t r = ::read(fd, buf, sizeof buf);
    if (r < 0) {
      if (errno == EINTR) continue;
      throw UrdfError(msg("URDF file '", shown, "' cannot be read: ", std::strerror(errno)));
    }
    if (r == 0) break;
    text.append(buf, static_cast<size_t>(r));
    if (text.size() > kUrdfMaxBytes)
      throw UrdfError(too_large(msg("URDF file '", shown, "'"), text.size()));
  }
  return text;
}

// the end of the markup at xml[i] ('<' there) that holds no attributes (comment, CDATA,
// processing instruction, declaration, end tag), or nullptr at a start tag
const char* markup_end(const std::string& xml, size_t i) {
  if (xml.compare(i, 4, "<!--") == 0) return "-->";
  if (xml.compare(i, 9, "<![CDATA[") == 0) return "]]>";
  if (xml.compare(i, 2, "<?") == 0) return "?>";
  if (xml.compare(i, 2, "<!") == 0 || xml.compare(i, 2, "</") == 0) return ">";
  return nullptr;
}

// moves i to just past the next `end` (or to the end of the text), counting lines
void skip_past(const std::string& xml, const char* end, size_t& i, long& line) {
  const size_t e = xml.find(end, i);
  const size_t stop = e == std::string::npos ? xml.size() : e + std::strlen(end);
  line +=
      std::count(xml.begin() + static_cast<long>(i), xml.begin() + static_cast<long>(stop), '\n');
  i = stop;
}

// the start tag at xml[i] ('<' there): counts the '=' outside quoted values up to its '>' and
// refuses more than kUrdfMaxAttributes; moves i past the '>', counting lines
void check_start_tag(const std::string& xml, const std::string& where, size_t& i, long& line) {
  const size_t n = xml.size();
  const long tag_line = line;
  const size_t name0 = ++i;
  while (i < n && !std::isspace(static_cast<unsigned char>(xml[i])) && xml[i] != '>' &&
         xml[i] != '/')
    ++i;
  const std::string name = xml.substr(name0, i - name0);
  long attributes = 0;
  char quote = 0;
  for (; i < n; ++i) {
    const char t = xml[i];
    if (t == '\n') ++line;
    if (quote) {
      if (t == quote) quote = 0;
    } else if (t == '"' || t == '\'') {
      quote = t;
    } else if (t == '=') {
      ++attributes;
    } else if (t == '>') {
      ++i;
      break;
    }
  }
  if (attributes > kUrdfMaxAttributes) {
    throw UrdfError(msg(where, ": element <", excerpt(name), "> on line ", tag_line, " has ",
                        attributes, " attributes, more than the limit of ", kUrdfMaxAttributes));
  }
}

}  // namespace

std::string read_source(const std::string& path_or_xml, std::string* where) {
  if (looks_like_xml(path_or_xml)) {
    *where = "URDF string";
    if (path_or_xml.size() > kUrdfMaxBytes)
      throw UrdfError(too_large("URDF string", path_or_xml.size()));
    return path_or_xml;
  }
  const std::string& path = path_or_xml;
  check_path_text(path);
  const std::string shown = shown_path(path);
  *where = msg("URDF file '", shown, "'");
  stat_regular_file(path, shown);
  return read_file(path, shown);
}

void prescan(const std::string& xml, const std::string& where) {
  if (const size_t z = xml.find('\0'); z != std::string::npos) {
    throw UrdfError(msg(where, ": contains a NUL byte at byte offset ", z));
  }
  const size_t n = xml.size();
  size_t i = 0;
  long line = 1;
  while (i < n) {
    const char c = xml[i];
    if (c == '\n') ++line;
    if (c != '<') {
      ++i;
      continue;
    }
    if (const char* end = markup_end(xml, i)) {
      skip_past(xml, end, i, line);
      continue;
    }
    check_start_tag(xml, where, i, line);
  }
}

}  // namespace armdyn::urdf_import
