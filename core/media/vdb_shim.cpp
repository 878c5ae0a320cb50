/* vdb_shim.cpp — the only C++ in murk: reads one scalar grid of an OpenVDB file with libopenvdb (Museth
 * 2013, "VDB: High-resolution sparse volumes with dynamic topology", ACM TOG 32(3)) and hands its active
 * tiles and leaves to murk's sparse grid builder through the C interface of vdb_shim.h.
 *
 * Memory: the grid is read whole (OpenVDB has no streaming reader), then its leaves are stolen from the
 * tree one by one and each is freed as soon as the sink has copied it; murk's bricks are allocated at the
 * size of a leaf's buffer, so the allocator reuses the freed buffers and the peak stays near one copy of
 * the grid (sparse.c). Delayed loading is off: it would map the file and keep its pages resident.
 *
 * Output: libopenvdb logs through log4cplus to std::cout / std::cerr. While it runs, both streams are
 * captured (one reader at a time), and what it said is appended to an error message; nothing reaches
 * murk's own output. */
#include "vdb_shim.h"

#include <openvdb/Grid.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <array>
#include <fstream>
#include <map>
#include <iostream>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::mutex reader_lock;

/* Redirects std::cout, std::cerr and std::clog into a string while alive. */
class Capture {
public:
    Capture() : out(std::cout.rdbuf(buf.rdbuf())), er(std::cerr.rdbuf(buf.rdbuf())), lg(std::clog.rdbuf(buf.rdbuf())) {}
    ~Capture()
    {
        std::cout.rdbuf(out);
        std::cerr.rdbuf(er);
        std::clog.rdbuf(lg);
    }
    Capture(const Capture &) = delete;
    Capture &operator=(const Capture &) = delete;
    /* What was logged, on one line, without terminal colour codes. */
    std::string text() const
    {
        std::string s = buf.str(), t;
        for (size_t i = 0; i < s.size(); i++) {
            if (s[i] == '\033') { /* ESC [ ... letter */
                while (i < s.size() && !((s[i] >= 'a' && s[i] <= 'z') || (s[i] >= 'A' && s[i] <= 'Z')))
                    i++;
                continue;
            }
            char c = s[i] == '\n' || s[i] == '\r' || s[i] == '\t' ? ' ' : s[i];
            if (!(c == ' ' && (t.empty() || t.back() == ' ')))
                t += c;
        }
        while (!t.empty() && t.back() == ' ')
            t.pop_back();
        return t;
    }

private:
    std::stringstream buf;
    std::streambuf *out, *er, *lg;
};

struct Failure {
    std::string msg;
};

/* A -1 from a sink callback: its message is in err already. */
struct SinkFailed {};

void check(int rc)
{
    if (rc != 0)
        throw SinkFailed();
}

std::string coord(const openvdb::Coord &c)
{
    return "(" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) + ")";
}

/* A name from the file as a message may show it: at most 60 bytes, anything but printable ASCII as '?'. */
std::string printable(const std::string &s)
{
    std::string out = s.substr(0, 60);
    for (char &c : out)
        if (c < 0x20 || c > 0x7e)
            c = '?';
    return out;
}

/* The names of the file's grids, quoted and comma-separated. */
std::string grid_names(openvdb::io::File &file)
{
    std::string s;
    for (auto it = file.beginName(); it != file.endName(); ++it)
        s += (s.empty() ? "'" : ", '") + *it + "'";
    return s.empty() ? "none" : s;
}

/* ---- a check of the file's framing before libopenvdb reads it ----------------------------------------
 * libopenvdb trusts the lengths and counts the file states: a metadata count, a string's length or a root
 * node's tile count that claims more than the file holds makes it allocate by the claim and loop on a failed
 * stream (a hang the fuzz harness found). So the parts that carry such claims are walked here first, each
 * against the bytes that remain: the header, the file's metadata, every grid descriptor (its offsets in
 * order inside the file), each grid's metadata and transform, and a float or double grid's root counts.
 * A float or double grid's tree is walked whole, as libopenvdb 10 reads it (Tree::readTopology, then
 * readBuffers): every node a child mask announces must be in the file, every value block's length must be
 * the one its node needs, a root child may appear once and at a node's origin, and each zip block of the
 * topology must inflate to its length. libopenvdb checks none of these before it allocates: a count past
 * the end of the file made it build a node per claim from a failed stream (1.4 GB from 18 KB, found by
 * fuzz_vdb), a raw block longer than its node overran the node's buffer, and a node that failed to read
 * was lost with its subtree (a leak). What this walk leaves to libopenvdb is only the content of the leaf
 * buffers' compressed blocks, whose failure it reports with the tree already owning the leaf. */
class Framing {
public:
    explicit Framing(const char *path) : in(path, std::ios::binary)
    {
        if (!in)
            throw Failure{"cannot open it"};
        in.seekg(0, std::ios::end);
        size = file_size = static_cast<uint64_t>(in.tellg());
        in.seekg(0);
    }
    void check()
    {
        if (u64() != 0x56444220u)
            throw Failure{"not a VDB file (bad magic)"};
        version = u32();
        if (version < 222 || version > 300)
            throw Failure{"OpenVDB file format version " + std::to_string(version) + "; murk reads 222 (OpenVDB 3) and later"};
        skip(8); /* library version */
        char offsets = static_cast<char>(u8());
        skip(36); /* uuid, as text */
        if (!offsets)
            throw Failure{"the file has no grid offsets (written as a stream); murk reads files written by io::File"};
        meta_map("the file's metadata");
        uint32_t grids = u32();
        for (uint32_t g = 0; g < grids; g++)
            descriptor(g);
    }

private:
    std::ifstream in;
    uint64_t size = 0, pos = 0, file_size = 0; /* size: the end of the part being walked */
    uint32_t version = 0;

    void need(uint64_t n, const std::string &what)
    {
        if (n > size - pos)
            throw Failure{"truncated: " + what + " at byte " + std::to_string(pos) + " claims " + std::to_string(n) +
                          " bytes, " + std::to_string(size - pos) + " remain"};
    }
    void read(void *p, uint64_t n, const std::string &what = "a field")
    {
        need(n, what);
        in.read(static_cast<char *>(p), static_cast<std::streamsize>(n));
        pos += n;
    }
    uint64_t u64() { uint64_t v; read(&v, 8); return v; }
    uint32_t u32() { uint32_t v; read(&v, 4); return v; }
    uint8_t u8() { uint8_t v; read(&v, 1); return v; }
    void skip(uint64_t n, const std::string &what = "a field")
    {
        need(n, what);
        seek(pos + n);
    }
    void seek(uint64_t p)
    {
        pos = p;
        in.seekg(static_cast<std::streamoff>(p));
    }
    std::string str(const std::string &what)
    {
        uint32_t n = u32();
        need(n, what);
        std::string s(n, '\0');
        read(&s[0], n);
        return s;
    }
    /* A MetaMap: a count, then (name, type name, byte count, value) each. */
    void meta_map(const std::string &what)
    {
        uint32_t n = u32();
        need(12ull * n, what + " (" + std::to_string(n) + " entries)");
        for (uint32_t i = 0; i < n; i++) {
            std::string name = str(what + ": a name"), type = str(what + ": a type name");
            uint32_t bytes = u32();
            /* libopenvdb reads a registered fixed-size type's value by its type's size, whatever the byte count
             * says: a count that differs would put its stream elsewhere than this walk (found by fuzz_vdb: a
             * string length then read from the middle of a value, 1.7 GB; seed vdb/meta_size_mismatch) */
            static const struct { const char *type; uint32_t bytes; } fixed[] = {
                {"bool", 1}, {"int32", 4}, {"int64", 8}, {"float", 4}, {"double", 8}, {"vec2i", 8}, {"vec2s", 8},
                {"vec2d", 16}, {"vec3i", 12}, {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16}, {"vec4s", 16},
                {"vec4d", 32}, {"mat4s", 64}, {"mat4d", 128}};
            for (const auto &f : fixed)
                if (type == f.type && bytes != f.bytes)
                    throw Failure{what + ": '" + printable(name) + "' is a " + type + " of " + std::to_string(bytes) +
                                  " bytes; a " + type + " has " + std::to_string(f.bytes)};
            if (type == "__delayedload" && bytes > 0)
                delayed_load(what, bytes);
            else
                skip(bytes, what + ": a value");
        }
    }
    /* io::DelayedLoadMetadata::readValue, which sizes its arrays by the count it reads and the size a blosc
     * header claims (found by fuzz_vdb: a 4 GB allocation): a leaf count no larger than the file could hold
     * (a leaf takes at least its 64-byte mask), then a mask of a byte per leaf and the leaves' compressed
     * sizes (8 bytes each; a length of 2^32 - 1 for none), each raw after a length 0 or a blosc block whose
     * header states that length uncompressed and its own length compressed; all of it inside the value's
     * byte count, since libopenvdb reads on from where the value ends for it, not where the count says. */
    void delayed_load(const std::string &what, uint32_t bytes)
    {
        const std::string where = what + ": file_delayed_load";
        need(bytes, where);
        uint64_t limit = size, stop = pos + bytes;
        size = stop;
        uint64_t count = u32();
        if (count > file_size / 64)
            throw Failure{where + " claims " + std::to_string(count) + " leaves; the file holds at most " +
                          std::to_string(file_size / 64)};
        for (uint64_t elem : {1u, 8u}) {
            uint32_t len = u32();
            if (elem == 8 && len == UINT32_MAX)
                break;
            if (len == 0) {
                skip(count * elem, where);
                continue;
            }
            if (len < 16)
                throw Failure{where + ": a blosc block of " + std::to_string(len) + " bytes, shorter than its header"};
            skip(4, where); /* blosc's header: versions, flags, type size; */
            uint32_t plain = u32();
            skip(4, where); /* block size */
            uint32_t packed = u32();
            if (plain != count * elem || packed != len)
                throw Failure{where + ": a blosc block of " + std::to_string(len) + " bytes whose header says " +
                              std::to_string(packed) + " bytes, " + std::to_string(plain) + " uncompressed, where " +
                              std::to_string(count * elem) + " are needed"};
            skip(len - 16, where);
        }
        size = limit;
        seek(stop);
    }
    /* A grid descriptor and the head of its grid: metadata, transform, root counts. */
    void descriptor(uint32_t g)
    {
        std::string name = str("a grid's name"), type = str("a grid's type");
        bool instance = !str("a grid's instance parent").empty(); /* an instance has no topology of its own */
        uint64_t grid = u64(), block = u64(), end = u64();
        if (!(pos <= grid && grid <= block && block <= end && end <= size))
            throw Failure{"grid " + std::to_string(g) + " ('" + name + "') has offsets " + std::to_string(grid) + ", " +
                          std::to_string(block) + ", " + std::to_string(end) + " outside the file's " +
                          std::to_string(size) + " bytes"};
        uint64_t next = end;
        uint64_t limit = size;
        size = block; /* the head lies before the grid's buffers */
        seek(grid);
        uint32_t compression = u32(); /* Archive::readGridCompression */
        meta_map("grid '" + name + "' metadata");
        transform(name);
        int vsize = type.rfind("Tree_float_5_4_3", 0) == 0 ? 4 : type.rfind("Tree_double_5_4_3", 0) == 0 ? 8 : 0;
        if (vsize && !instance) {
            static const std::string half = "_HalfFloat";
            bool is_half = type.size() > half.size() && type.compare(type.size() - half.size(), half.size(), half) == 0;
            tree(Tree{name, static_cast<uint64_t>(vsize), is_half ? 2u : static_cast<uint64_t>(vsize), compression},
                 block, end);
        }
        size = limit;
        seek(next);
    }

    /* One grid's tree as the walk sees it: its value size in memory and in the file, its compression flags. */
    struct Tree {
        std::string name;
        uint64_t vsize, fsize;
        uint32_t compression;
    };
    enum { ZIP = 0x1, ACTIVE_MASK = 0x2, BLOSC = 0x4 }; /* io::COMPRESS_* */

    static uint64_t popcount(const uint64_t *w, uint64_t words)
    {
        uint64_t n = 0;
        for (uint64_t i = 0; i < words; i++)
            n += static_cast<uint64_t>(__builtin_popcountll(w[i]));
        return n;
    }
    /* Tree::readTopology (a buffer count, the root's background, tiles and children, each child's subtree),
     * then Tree::readBuffers: each leaf's values, in the order libopenvdb reads them (root children by
     * origin, as its std::map holds them; inside a node by index). */
    void tree(const Tree &t, uint64_t block, uint64_t end)
    {
        const std::string root = "grid '" + t.name + "' root";
        skip(4 + t.vsize, root);
        uint64_t tiles = u32(), children = u32();
        need(tiles * (13 + t.vsize) + children * 12, root + " (" + std::to_string(tiles) + " tiles, " +
             std::to_string(children) + " children)");
        skip(tiles * (13 + t.vsize), root + " tiles");
        std::map<std::array<int32_t, 3>, std::vector<uint16_t>> kids; /* each root child's leaves' active counts */
        for (uint64_t c = 0; c < children; c++) {
            std::array<int32_t, 3> o;
            read(o.data(), 12, root + " children");
            if ((o[0] | o[1] | o[2]) & 4095)
                throw Failure{root + ": a child at (" + std::to_string(o[0]) + ", " + std::to_string(o[1]) + ", " +
                              std::to_string(o[2]) + "), not at a multiple of 4096"};
            auto slot = kids.emplace(o, std::vector<uint16_t>());
            if (!slot.second)
                throw Failure{root + ": two children at (" + std::to_string(o[0]) + ", " + std::to_string(o[1]) +
                              ", " + std::to_string(o[2]) + ")"};
            internal(t, 5, slot.first->second);
        }
        if (pos != block)
            throw Failure{"grid '" + t.name + "': its topology ends at byte " + std::to_string(pos) +
                          ", its buffers are said to begin at " + std::to_string(block)};
        size = end; /* the buffers lie before the grid's end */
        for (const auto &k : kids)
            for (uint16_t on : k.second) {
                skip(64, "grid '" + t.name + "' a leaf's value mask");
                values(t, 512, on, 64, false);
            }
    }
    /* InternalNode::readTopology: child and value masks, the node's values, then each child in index order
     * (log2 5: the root's children, log2 4: theirs; a leaf's topology is its value mask). */
    void internal(const Tree &t, int log2, std::vector<uint16_t> &leaves)
    {
        const uint64_t n = 1ull << (3 * log2), words = n / 64;
        std::vector<uint64_t> child(words), value(words);
        const std::string masks = "grid '" + t.name + "' a node's masks";
        read(child.data(), n / 8, masks);
        read(value.data(), n / 8, masks);
        values(t, n, popcount(value.data(), words), n / 8, true);
        for (uint64_t w = 0; w < words; w++)
            for (uint64_t bits = child[w]; bits; bits &= bits - 1) {
                if (log2 == 5) {
                    internal(t, 4, leaves);
                } else {
                    uint64_t mask[8];
                    read(mask, 64, "grid '" + t.name + "' a leaf's value mask");
                    leaves.push_back(static_cast<uint16_t>(popcount(mask, 8)));
                }
            }
    }
    /* io::readCompressedValues for a node of n values, `on` of them active, whose masks have mask_bytes:
     * a flag, up to two inactive values, a selection mask, then the values (only the active ones under mask
     * compression), raw or in a zip or blosc block with its signed length first. inflate: check that a zip
     * block inflates to its length (a topology block: libopenvdb loses the node when it does not). */
    void values(const Tree &t, uint64_t n, uint64_t on, uint64_t mask_bytes, bool inflate)
    {
        const std::string what = "grid '" + t.name + "' values";
        int8_t flag = static_cast<int8_t>(u8());
        if (flag == 2 || flag == 4 || flag == 5)
            skip(t.vsize * (flag == 5 ? 2 : 1), what);
        if (flag == 3 || flag == 4 || flag == 5)
            skip(mask_bytes, what);
        uint64_t count = (t.compression & ACTIVE_MASK) && flag != 6 ? on : n;
        if (t.fsize != t.vsize && count == 0)
            return; /* io::HalfReader reads nothing for no values */
        uint64_t bytes = count * t.fsize;
        if (!(t.compression & (ZIP | BLOSC))) {
            skip(bytes, what);
            return;
        }
        int64_t len = static_cast<int64_t>(u64());
        if (len <= 0) {
            if (len == INT64_MIN || static_cast<uint64_t>(-len) != bytes)
                throw Failure{what + ": a block of " + std::to_string(len) + " bytes where " +
                              std::to_string(bytes) + " are stored uncompressed"};
            skip(bytes, what);
            return;
        }
        need(static_cast<uint64_t>(len), what + " (a compressed block)");
        if (inflate && !(t.compression & BLOSC)) {
            std::vector<Bytef> in(static_cast<size_t>(len)), out(bytes ? bytes : 1);
            read(in.data(), static_cast<uint64_t>(len));
            uLongf got = static_cast<uLongf>(bytes);
            if (uncompress(out.data(), &got, in.data(), static_cast<uLong>(len)) != Z_OK || got != bytes)
                throw Failure{what + ": a zip block at byte " + std::to_string(pos - static_cast<uint64_t>(len)) +
                              " does not inflate to " + std::to_string(bytes) + " bytes"};
            return;
        }
        skip(static_cast<uint64_t>(len), what);
    }
    /* Transform::read: a map type name, then the map (its size by type; a frustum is refused later). */
    void transform(const std::string &name)
    {
        std::string map = str("grid '" + name + "' transform");
        static const std::pair<const char *, uint64_t> sizes[] = {
            {"AffineMap", 128}, {"UnitaryMap", 128}, {"ScaleMap", 120}, {"UniformScaleMap", 120},
            {"ScaleTranslateMap", 144}, {"UniformScaleTranslateMap", 144}, {"TranslationMap", 24}};
        for (const auto &m : sizes)
            if (map == m.first) {
                skip(m.second, "grid '" + name + "' " + map);
                return;
            }
        throw Failure{"grid '" + name + "' has a non-linear (" + map.substr(0, 64) + ") transform; murk takes affine maps"};
    }
};

/* Tiles first (at every level above the leaves), then the leaves, stolen from the tree and freed one by one. */
template <typename GridT> void send(GridT &grid, const murk_vdb_sink *sink, char *err, size_t errlen)
{
    using TreeT = typename GridT::TreeType;
    using LeafT = typename TreeT::LeafNodeType;
    TreeT &tree = grid.tree();
    auto tiles = tree.cbeginValueOn();
    tiles.setMaxDepth(tiles.getLeafDepth() - 1);
    for (; tiles; ++tiles) {
        openvdb::CoordBBox bb;
        tiles.getBoundingBox(bb);
        double v = static_cast<double>(*tiles);
        int o[3] = {bb.min().x(), bb.min().y(), bb.min().z()};
        float f = static_cast<float>(v);
        if (std::isfinite(v) && !std::isfinite(f))
            throw Failure{"a tile value " + std::to_string(v) + " is beyond the range of float"};
        check(sink->tile(sink->user, o, static_cast<long long>(bb.dim().x()), f, err, errlen));
    }
    std::vector<LeafT *> leaves;
    leaves.reserve(tree.leafCount());
    tree.stealNodes(leaves);
    float values[LeafT::SIZE];
    uint64_t mask[LeafT::SIZE / 64];
    size_t i = 0;
    try {
        for (; i < leaves.size(); i++) {
            LeafT *leaf = leaves[i];
            const auto *data = leaf->buffer().data();
            for (openvdb::Index k = 0; k < LeafT::SIZE; k++) {
                values[k] = static_cast<float>(data[k]);
                if (std::isfinite(static_cast<double>(data[k])) && !std::isfinite(values[k]) &&
                    leaf->getValueMask().isOn(k))
                    throw Failure{"value " + std::to_string(static_cast<double>(data[k])) + " at voxel " +
                                  coord(leaf->offsetToGlobalCoord(k)) + " is beyond the range of float"};
            }
            for (openvdb::Index w = 0; w < LeafT::SIZE / 64; w++)
                mask[w] = leaf->getValueMask().template getWord<uint64_t>(w);
            const openvdb::Coord &c = leaf->origin();
            int o[3] = {c.x(), c.y(), c.z()};
            delete leaf;
            leaves[i] = nullptr;
            check(sink->leaf(sink->user, o, values, mask, err, errlen));
        }
    } catch (...) {
        for (; i < leaves.size(); i++)
            delete leaves[i];
        throw;
    }
}

void read_grid(const char *path, const char *name, uint64_t max_active, const murk_vdb_sink *sink, murk_vdb_meta *meta,
               char *err, size_t errlen)
{
    try {
        Framing(path).check();
    } catch (const Failure &f) {
        throw Failure{"not a readable OpenVDB file: " + f.msg};
    }
    openvdb::io::File file(path);
    file.open(false); /* no delayed loading */
    std::string gname;
    if (name) {
        if (!file.hasGrid(name)) {
            meta->no_such_grid = 1;
            throw Failure{std::string("no grid '") + name + "'; the file has " + grid_names(file)};
        }
        gname = name;
    } else {
        int n = 0;
        for (auto it = file.beginName(); it != file.endName(); ++it, n++)
            gname = *it;
        if (n != 1)
            throw Failure{"the file holds " + std::to_string(n) + " grids (" + grid_names(file) +
                          "); name one with grid: NAME"};
    }
    openvdb::GridBase::Ptr head = file.readGridMetadata(gname);
    const std::string type = head->valueType();
    if (type != "float" && type != "double")
        throw Failure{"grid '" + gname + "' holds " + type + " values; murk reads scalar float, half or double grids"};
    if (head->getGridClass() == openvdb::GRID_LEVEL_SET)
        throw Failure{"grid '" + gname + "' is a level set (signed distances), not a density (a fog volume); "
                      "convert it, e.g. with openvdb::tools::sdfToFogVolume"};
    auto claimed = head->getMetadata<openvdb::Int64Metadata>(openvdb::GridBase::META_FILE_VOXEL_COUNT);
    if (claimed && (claimed->value() < 0 || static_cast<uint64_t>(claimed->value()) > max_active))
        throw Failure{"grid '" + gname + "' has " + std::to_string(claimed->value()) +
                      " active voxels, more than the limit of " + std::to_string(max_active)};
    openvdb::GridBase::Ptr g = file.readGrid(gname);
    file.close();
    const openvdb::math::Transform &xf = g->transform();
    if (!xf.isLinear())
        throw Failure{"grid '" + gname + "' has a non-linear (" + xf.mapType() + ") transform; murk takes affine maps"};
    openvdb::math::Mat4d m = xf.baseMap()->getAffineMap()->getMat4(); /* row vectors: world = ijk * m */
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            meta->map[4 * r + c] = m(c, r);
        meta->map[4 * r + 3] = m(3, r);
    }
    openvdb::CoordBBox bb = g->evalActiveVoxelBoundingBox();
    if (bb.empty())
        throw Failure{"grid '" + gname + "' has no active voxels"};
    int bmin[3] = {bb.min().x(), bb.min().y(), bb.min().z()}, bmax[3] = {bb.max().x(), bb.max().y(), bb.max().z()};
    check(sink->begin(sink->user, bmin, bmax, err, errlen));
    if (auto fg = openvdb::gridPtrCast<openvdb::FloatGrid>(g)) {
        meta->background = fg->background();
        send(*fg, sink, err, errlen);
    } else if (auto dg = openvdb::gridPtrCast<openvdb::DoubleGrid>(g)) {
        meta->background = dg->background();
        send(*dg, sink, err, errlen);
    } else {
        throw Failure{"grid '" + gname + "' is of type " + g->type() + "; murk reads float, half or double trees of "
                      "OpenVDB's standard configuration (5, 4, 3)"};
    }
}

} // namespace

extern "C" int murk_vdb_read(const char *path, const char *grid, uint64_t max_active, const murk_vdb_sink *sink,
                             murk_vdb_meta *meta, char *err, size_t errlen)
{
    static std::once_flag init;
    std::lock_guard<std::mutex> hold(reader_lock);
    *meta = murk_vdb_meta();
    std::string what;
    {
        Capture quiet;
        try {
            std::call_once(init, [] { openvdb::initialize(); });
            read_grid(path, grid, max_active, sink, meta, err, errlen);
            return 0;
        } catch (const SinkFailed &) {
            return -1;
        } catch (const Failure &f) {
            what = f.msg;
        } catch (const std::bad_alloc &) {
            what = "out of memory";
        } catch (const std::exception &e) {
            what = std::string("not a readable OpenVDB file: ") + e.what();
        } catch (...) {
            what = "not a readable OpenVDB file";
        }
        std::string said = quiet.text();
        if (!said.empty())
            what += " (openvdb: " + said + ")";
    }
    if (err && errlen)
        std::snprintf(err, errlen, "%s: %s", path, what.c_str());
    return -1;
}
