// sinew_example.cpp -- Sinew from C++: RAII over the caller-owned memory,
// std::vector buffers, exceptions for status codes. C++11 and later; built
// by tests/scripts/test_integration.sh with -std=c++11 and -std=c++17
// (-Wall -Wextra -Wpedantic -Werror) against libsinew.a, fixed and float.
//   sinew_example BLOB [STEPS]
// Steps the cow with the integration pose sequence (sn_wiggle.h), takes a
// snapshot half way (an instance is plain memory: copying it is a snapshot),
// rolls back to it, replays, and prints "hash: <hex>" (the consumers' hash).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "sinew.h"
#include "sn_wiggle.h"

namespace sinew {

// Throws on anything but SN_OK, with the runtime's own message.
inline void check(sn_status s, const char *what) {
    if (s != SN_OK) throw std::runtime_error(std::string(what) + ": " + sn_status_str(s));
}

// A validated blob in 8-byte aligned storage it owns. Immutable once built:
// share one Blob (const) between every instance and thread.
class Blob {
public:
    explicit Blob(const std::string &path) {
        std::ifstream in(path.c_str(), std::ios::binary);
        std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (!in.good() && !in.eof()) throw std::runtime_error("cannot read " + path);
        words_.resize((bytes.size() + 7) / 8);
        if (!bytes.empty()) std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char *>(words_.data()));
        check(sn_blob_validate(words_.data(), bytes.size(), &blob_), path.c_str());
        sn_blob_get_info(blob_, &info_);
    }
    Blob(const Blob &) = delete;             // blob_ points into words_
    Blob &operator=(const Blob &) = delete;
    const sn_blob *get() const { return blob_; }
    const sn_blob_info &info() const { return info_; }

private:
    std::vector<std::uint64_t> words_;       // uint64_t: 8-byte alignment
    const sn_blob *blob_ = nullptr;
    sn_blob_info info_;
};

// One instance in memory it owns. Copyable: the copy is a snapshot (the
// runtime keeps no pointers inside an instance), assignment rolls back.
class Instance {
public:
    explicit Instance(const Blob &blob)
        : mem_((sn_instance_size(blob.get()) + 7) / 8) {
        sn_instance *inst = nullptr;
        check(sn_instance_init(mem_.data(), mem_.size() * 8, blob.get(), &inst), "instance");
        offset_ = reinterpret_cast<char *>(inst) - reinterpret_cast<char *>(mem_.data());
    }
    Instance(const Instance &) = default;
    Instance &operator=(const Instance &) = default;
    Instance(Instance &&) = default;
    Instance &operator=(Instance &&) = default;

    sn_instance *get() { return reinterpret_cast<sn_instance *>(reinterpret_cast<char *>(mem_.data()) + offset_); }
    const sn_instance *get() const {
        return reinterpret_cast<const sn_instance *>(reinterpret_cast<const char *>(mem_.data()) + offset_);
    }
    void set_pose(const std::vector<sn_xform> &pose) {
        check(sn_set_pose(get(), pose.data(), static_cast<std::uint32_t>(pose.size())), "pose");
    }
    void step() { sn_step(get()); }
    std::uint64_t hash() const { return sn_state_hash(get()); }
    void surface(std::vector<sn_vec3> &out, std::uint32_t n) const {
        out.resize(n);
        check(sn_get_surface(get(), out.data(), 0, n), "surface");
    }

private:
    std::vector<std::uint64_t> mem_;
    std::ptrdiff_t offset_ = 0;
};

} // namespace sinew

static std::string hex(std::uint64_t h) {
    char s[17];
    sn_wiggle_hex(h, s);
    return s;
}

int main(int argc, char **argv) {
    if (argc < 2) { std::fprintf(stderr, "usage: sinew_example BLOB [STEPS]\n"); return 2; }
    const std::uint32_t steps = argc > 2 ? static_cast<std::uint32_t>(std::strtoul(argv[2], nullptr, 10)) : 200u;
    try {
        const sinew::Blob cow(argv[1]);
        const sn_blob_info &info = cow.info();
        sinew::Instance inst(cow);
        std::vector<sn_quat> local(info.joints);
        std::vector<sn_xform> pose(info.joints);
        std::vector<sn_vec3> verts;
        auto advance = [&](sinew::Instance &in, std::uint32_t from, std::uint32_t to) {
            for (std::uint32_t k = from; k < to; k++) {
                sn_wiggle_pose(cow.get(), info.joints, k, 0, local.data(), pose.data());
                in.set_pose(pose);
                in.step();
            }
        };
        const std::uint32_t half = steps / 2;
        advance(inst, 0, half);
        const sinew::Instance snapshot = inst;        // copy = snapshot
        advance(inst, half, steps);
        const std::uint64_t first = inst.hash();
        inst = snapshot;                              // roll back, replay
        advance(inst, half, steps);
        if (inst.hash() != first) { std::printf("FAIL: replay after rollback differs\n"); return 1; }
        inst.surface(verts, info.surface_vertices);
        std::printf("flavour: %s\nsurface vertices: %zu\nsteps: %u\nhash: %s\n",
                    SN_FLAVOUR ? "float" : "fixed", verts.size(), static_cast<unsigned>(steps),
                    hex(inst.hash()).c_str());
    } catch (const std::exception &e) {
        std::fprintf(stderr, "sinew_example: %s\n", e.what());
        return 1;
    }
    return 0;
}
