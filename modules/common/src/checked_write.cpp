// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>

#include <cerrno>
#include <cstring>
#include <streambuf>
#include <thread>

#include <fcntl.h>
#include <unistd.h>

namespace msf {

namespace {

/// A file written with write(2), whose first failure is kept (later writes are dropped) and
/// reported, with close(2)'s, by close().
class CheckedFile {
public:
  CheckedFile(const std::string& path, const std::string& shown) : shown_(shown) {
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0)
      error_ = errno;
  }
  ~CheckedFile() {
    if (fd_ >= 0)
      ::close(fd_);
  }
  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;

  bool ok() const { return error_ == 0; }

  void write(const char* data, std::size_t size) {
    while (size > 0 && error_ == 0) {
      const ssize_t n = ::write(fd_, data, size);
      if (n < 0 && errno == EINTR)
        continue;
      if (n <= 0) {
        error_ = n < 0 ? errno : EIO;
        return;
      }
      data += n;
      size -= static_cast<std::size_t>(n);
    }
  }

  /// Throws IOError naming the file with the first failure's reason.
  void close() {
    if (fd_ >= 0 && ::close(fd_) != 0 && error_ == 0)
      error_ = errno;
    fd_ = -1;
    if (error_ != 0)
      throw IOError("cannot write '" + shown_ + "': " + std::strerror(error_));
  }

private:
  std::string shown_;
  int fd_ = -1;
  int error_ = 0;
};

/// A std::streambuf over a CheckedFile.
class CheckedBuffer : public std::streambuf {
public:
  explicit CheckedBuffer(CheckedFile& file) : file_(file) { setp(buffer_, buffer_ + sizeof buffer_); }

protected:
  int_type overflow(int_type c) override {
    if (sync() != 0)
      return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* data, std::streamsize size) override {
    if (size < static_cast<std::streamsize>(sizeof buffer_))
      return std::streambuf::xsputn(data, size);
    if (sync() != 0)
      return 0;
    file_.write(data, static_cast<std::size_t>(size)); // a large block: not through the buffer
    return file_.ok() ? size : 0;
  }
  int sync() override {
    file_.write(pbase(), static_cast<std::size_t>(pptr() - pbase()));
    setp(buffer_, buffer_ + sizeof buffer_);
    return file_.ok() ? 0 : -1;
  }

private:
  CheckedFile& file_;
  char buffer_[1 << 16];
};

} // namespace

void writeStreamAtomically(const std::string& path, const std::function<void(std::ostream& out)>& write) {
  writeAtomically(path, [&](const std::string& tmp) {
    CheckedFile file(tmp, path);
    CheckedBuffer buffer(file);
    std::ostream out(&buffer);
    try {
      if (file.ok())
        write(out);
      out.flush();
    } catch (...) {
      file.close(); // a failed write is the reason a writer gave up: name it
      throw;
    }
    file.close();
  });
}

void writeBytesAtomically(const std::string& path, const void* data, std::size_t size) {
  writeAtomically(path, [&](const std::string& tmp) {
    CheckedFile file(tmp, path);
    file.write(static_cast<const char*>(data), size);
    file.close();
  });
}

void writeThroughPipeAtomically(const std::string& path, const std::function<void(const std::string& sink)>& write) {
  writeAtomically(path, [&](const std::string& tmp) {
    CheckedFile file(tmp, path);
    int ends[2];
    if (::pipe2(ends, O_CLOEXEC) != 0)
      throw IOError("cannot write '" + path + "': pipe: " + std::strerror(errno));
    // The copy reads to the end whatever happens, so the writer never blocks on a full pipe.
    std::thread copy([&file, in = ends[0]] {
      char chunk[1 << 16];
      for (;;) {
        const ssize_t n = ::read(in, chunk, sizeof chunk);
        if (n < 0 && errno == EINTR)
          continue;
        if (n <= 0)
          break;
        file.write(chunk, static_cast<std::size_t>(n));
      }
    });
    // The pipe ends when the writer's and this write end are closed: close ours in any case.
    struct Finish {
      int in, out;
      std::thread& copy;
      ~Finish() {
        ::close(out);
        copy.join();
        ::close(in);
      }
    };
    try {
      Finish finish{ends[0], ends[1], copy};
      write("/proc/self/fd/" + std::to_string(ends[1]));
    } catch (...) {
      file.close();
      throw;
    }
    file.close();
  });
}

} // namespace msf
