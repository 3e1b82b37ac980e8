#pragma once
// An environment variable set or unset for one scope: the destructor puts back what was
// there (set to its old value, or unset), also when a REQUIRE throws out of the test.
#include <cstdlib>
#include <optional>
#include <string>

namespace bounce::test {

class scoped_environment {
public:
    explicit scoped_environment(std::string name) : name_(std::move(name)) {
        if (const char* v = std::getenv(name_.c_str())) saved_ = v;
    }
    scoped_environment(const scoped_environment&) = delete;
    scoped_environment& operator=(const scoped_environment&) = delete;
    ~scoped_environment() {
        if (saved_) ::setenv(name_.c_str(), saved_->c_str(), 1);
        else ::unsetenv(name_.c_str());
    }

    void set(const std::string& value) const { ::setenv(name_.c_str(), value.c_str(), 1); }
    void unset() const { ::unsetenv(name_.c_str()); }

private:
    std::string name_;
    std::optional<std::string> saved_;
};

}  // namespace bounce::test
