// Input files a user might hand the solver by mistake, or on purpose: every
// one is refused with an InputError that names the file, the field and what is
// allowed, and none crashes, hangs or echoes megabytes back.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "engine/input/input_reader.hpp"

namespace flocsim::input {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path p =
      fs::temp_directory_path() / ("flocsim_input_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

std::string refusal_of_file(const fs::path& file) {
  try {
    read_json_file(file.string());
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " was accepted";
  return "";
}

TEST(InputFile, DeepNestingIsRefusedNotACrash) {
  // 100,000 nested arrays (200 kB) crashed the reader with SIGSEGV: every
  // recursive walk of such a document (parse, copy, dump, destruction)
  // exhausts the stack.
  const int depth = 100000;
  const fs::path f = write_file(
      "deep.json", "{\"scene\": \"fluid\", \"fluid\": {\"size\": " + std::string(depth, '[') +
                       std::string(depth, ']') + "}}");
  const std::string why = refusal_of_file(f);
  EXPECT_THAT(why, AllOf(HasSubstr(f.string()), HasSubstr("fluid.size[0]"),
                         HasSubstr("nested deeper than 64 levels")));
  EXPECT_LT(why.size(), 400u);  // the path into the nesting is cut short
  // 64 levels are fine (the limit is on depth, not on nesting as such)
  const fs::path ok = write_file("ok.json", std::string(63, '[') + std::string(63, ']'));
  EXPECT_NO_THROW(read_json_file(ok.string()));
  fs::remove(f);
  fs::remove(ok);
}

TEST(InputFile, DuplicateKeyIsRefusedNamingIt) {
  // JSON readers keep the last of two equal keys: a case ran with viscosity
  // 0.5 where the first key said 0.05.
  const fs::path f =
      write_file("dup.json", R"({"scene": "fluid", "fluid": {"viscosity": 0.05, "size": [8, 8, 8],
                      "viscosity": 0.5}})");
  EXPECT_THAT(refusal_of_file(f), AllOf(HasSubstr("fluid.viscosity"), HasSubstr("twice")));
  // the same key in two different objects is not a duplicate
  const fs::path ok =
      write_file("nodup.json", R"({"a": {"x": 1}, "b": {"x": 1}, "c": [{"x": 1}, {"x": 2}]})");
  EXPECT_NO_THROW(read_json_file(ok.string()));
  fs::remove(f);
  fs::remove(ok);
}

TEST(InputFile, NumberBeyondDoubleNamesFieldAndLine) {
  const fs::path f =
      write_file("ovf.json", "{\"scene\": \"fluid\",\n \"fluid\": {\n  \"viscosity\": 1e999}}");
  EXPECT_THAT(refusal_of_file(f),
              AllOf(HasSubstr(f.string()), HasSubstr("fluid.viscosity = 1e999"),
                    HasSubstr("beyond the range of double"), HasSubstr("line 3")));
  fs::remove(f);
}

TEST(InputFile, SyntaxErrorNamesFileAndPlace) {
  const fs::path f = write_file("bad.json", "{\"fluid\": {\"size\": [8, 8,, 8]}}");
  EXPECT_THAT(refusal_of_file(f), AllOf(HasSubstr(f.string()), HasSubstr("not valid JSON"),
                                        HasSubstr("column"), HasSubstr("fluid.size[2]")));
  fs::remove(f);
}

TEST(InputFile, LargeFileIsRefusedBeforeItIsRead) {
  // 50 MB took 20 s and 2.1 GB before it was refused, and the whole array
  // was echoed. The size is checked first: the refusal takes no time.
  const fs::path f = write_file("big.json", "");
  fs::resize_file(f, 50u << 20);
  const auto t0 = std::chrono::steady_clock::now();
  const std::string why = refusal_of_file(f);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_THAT(why, AllOf(HasSubstr(f.string()), HasSubstr("at most 4 MiB")));
  EXPECT_LT(seconds, 1.0);
  fs::remove(f);
}

TEST(InputFile, ALongValueIsShownCutShort) {
  // Below the size limit a wrong value is refused by the case reader, whose
  // message shows the start of the value and its length only.
  std::string list = "[0";
  for (int i = 1; i < 100000; ++i) list += "," + std::to_string(i);
  list += "]";
  const nlohmann::json doc = nlohmann::json::parse("{\"size\": " + list + "}");
  InputReader in(doc, "fluid");
  try {
    in.numbers("size", 3, {});
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string why = e.what();
    EXPECT_THAT(why, AllOf(HasSubstr("fluid.size = [0,1,2"), HasSubstr("characters)"),
                           HasSubstr("must be an array of 3 numbers")));
    EXPECT_LT(why.size(), 300u);
  }
}

// A whole number written as JSON allows (2000.0, 2e3, stored as floating
// point by the reader) was refused as "1000.0: must be an integer", while a
// sweep axis took 2000.0 as 2000. It is the same number now; a fraction is
// refused as not whole, a value beyond the range by the range.
TEST(InputFile, AWholeNumberWrittenWithAnExponentIsAnInteger) {
  const nlohmann::json doc =
      nlohmann::json::parse(R"({"a": 1e3, "b": 2000.0, "c": 7, "d": 1.5, "e": 1e20, "f": -0.0})");
  InputReader in(doc, "run");
  const Range steps{.at_least = 0, .at_most = 1e12};
  EXPECT_EQ(in.integer("a", steps), 1000);
  EXPECT_EQ(in.integer("b", steps), 2000);
  EXPECT_EQ(in.integer("c", steps), 7);
  EXPECT_EQ(in.integer("f", steps), 0);
  const auto refusal = [&](const std::string& key) {
    try {
      in.integer(key, steps);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refusal("d"), "run.d = 1.5: must be a whole number >= 0 and <= 1e+12");
  EXPECT_EQ(refusal("e"), "run.e = 1e+20: must be >= 0 and <= 1e+12");
  long x = 0;
  EXPECT_FALSE(whole_number(nlohmann::json(9007199254740994.0), x));  // past 2^53
  EXPECT_TRUE(whole_number(nlohmann::json(9007199254740992.0), x));
  EXPECT_EQ(x, 9007199254740992L);
}

// The JSON reader stops at a NUL byte, so `{...}` NUL `junk` was read as the
// valid part alone; a NUL byte anywhere is refused, with where it is.
TEST(InputFile, ANulByteIsRefusedNotTakenForTheEnd) {
  const fs::path f = write_file("nul.json", std::string("{\"scene\": \"fluid\"}\0junk", 23));
  EXPECT_THAT(refusal_of_file(f),
              AllOf(HasSubstr("a NUL byte at offset 18"), HasSubstr("JSON text never holds")));
  fs::remove(f);
}

TEST(InputFile, DirectoryAndMissingFileAreNamed) {
  const fs::path dir = write_file("adir", "");
  fs::remove(dir);
  fs::create_directory(dir);
  EXPECT_THAT(refusal_of_file(dir), AllOf(HasSubstr(dir.string()), HasSubstr("is a directory")));
  fs::remove(dir);
  EXPECT_THAT(refusal_of_file(dir), AllOf(HasSubstr(dir.string()), HasSubstr("no such file")));
}

TEST(InputFile, APipeOrDeviceIsRefusedWithoutBlocking) {
  // A FIFO with no writer blocked the reader forever; /dev/zero never ends.
  const fs::path fifo = write_file("fifo", "");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THAT(refusal_of_file(fifo), HasSubstr("not a regular file"));
  fs::remove(fifo);
  EXPECT_THAT(refusal_of_file("/dev/zero"), HasSubstr("not a regular file"));
}

}  // namespace
}  // namespace flocsim::input
