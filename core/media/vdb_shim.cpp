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

#include <cmath>
#include <cstdio>
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

/* The names of the file's grids, quoted and comma-separated. */
std::string grid_names(openvdb::io::File &file)
{
    std::string s;
    for (auto it = file.beginName(); it != file.endName(); ++it)
        s += (s.empty() ? "'" : ", '") + *it + "'";
    return s.empty() ? "none" : s;
}

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
