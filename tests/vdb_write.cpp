/* vdb_write.cpp — writes small OpenVDB files for the tests (built only in the test build, against libopenvdb).
 *
 *   vdb_write OUT.vdb < SPEC
 *
 * SPEC is one command per line ('#' starts a comment); `grid` starts a grid, the commands after it fill it:
 *   grid NAME TYPE          TYPE: float | half (a float grid saved as half) | double | vec3s | int32 | levelset
 *   map SX SY SZ TX TY TZ [RX RY RZ]
 *                           index to world: scale, then rotate (degrees about x, y, z), then translate
 *   frustum                 a non-linear (frustum) transform
 *   background V
 *   voxel X Y Z V           an active voxel (V may be nan or inf, to write bad files)
 *   inactive X Y Z V        a voxel holding V, inactive
 *   fill X0 Y0 Z0 X1 Y1 Z1 V    active V over the inclusive box (OpenVDB makes tiles where it can)
 *   vol FILE                the voxels of a Mitsuba .vol (1 channel float32): voxel (x, y, z) at index (x, y, z),
 *                           active where it is not 0, and the map that puts the voxel centres where the .vol
 *                           puts them
 *   checker X0 Y0 Z0 N A B  N^3 voxels from (X0, Y0, Z0), A and B alternating per voxel, all active
 *   ball C R                voxels within R of (C, C, C), 1 - r / R (+ a hash of the voxel / 4096): written
 *                           leaf by leaf (fast for millions of voxels); plus active voxels at (0,0,0) and
 *                           (2C, 2C, 2C) so the box spans 2C + 1 voxels
 *   compress none | zip | blosc     (default none; inactive values are always left out, OpenVDB's active-mask
 *                           compression)
 * Exit status 0, or 1 with a message. */
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <openvdb/math/Transform.h>
#include <openvdb/tools/Prune.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using openvdb::Coord;

namespace {

struct Spec {
    std::string name, type;
    openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(1.0);
    openvdb::FloatGrid::Ptr f;       /* float, half, levelset */
    openvdb::DoubleGrid::Ptr d;
    openvdb::Vec3SGrid::Ptr v;
    openvdb::Int32Grid::Ptr i;
};

[[noreturn]] void die(const std::string &msg)
{
    std::fprintf(stderr, "vdb_write: %s\n", msg.c_str());
    std::exit(1);
}

void set(Spec &g, const Coord &c, double v, bool on)
{
    if (g.f)
        g.f->tree().setValue(c, static_cast<float>(v)), g.f->tree().setActiveState(c, on);
    else if (g.d)
        g.d->tree().setValue(c, v), g.d->tree().setActiveState(c, on);
    else if (g.v)
        g.v->tree().setValue(c, openvdb::Vec3s(static_cast<float>(v))), g.v->tree().setActiveState(c, on);
    else
        g.i->tree().setValue(c, static_cast<int>(v)), g.i->tree().setActiveState(c, on);
}

uint64_t hash(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdull;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ull;
    return x ^ (x >> 33);
}

/* A ball of radius r around (c, c, c), leaf by leaf. */
void ball(openvdb::FloatGrid &g, int c, double r)
{
    using Leaf = openvdb::FloatTree::LeafNodeType;
    int lo = static_cast<int>(std::floor(c - r)) & ~7, hi = static_cast<int>(std::ceil(c + r));
    for (int x = lo; x <= hi; x += 8)
        for (int y = lo; y <= hi; y += 8)
            for (int z = lo; z <= hi; z += 8) {
                auto *leaf = new Leaf(Coord(x, y, z), 0.0f, false);
                bool any = false;
                for (openvdb::Index k = 0; k < Leaf::SIZE; k++) {
                    Coord p = leaf->offsetToGlobalCoord(k);
                    double dx = p.x() - c, dy = p.y() - c, dz = p.z() - c, d = std::sqrt(dx * dx + dy * dy + dz * dz);
                    if (d <= r) {
                        uint64_t h = hash(static_cast<uint64_t>(p.x()) * 73856093u ^ static_cast<uint64_t>(p.y()) *
                                          19349663u ^ static_cast<uint64_t>(p.z()) * 83492791u);
                        leaf->setValueOn(k, static_cast<float>(1.0 - d / r + static_cast<double>(h % 1024u) / 4096.0));
                        any = true;
                    }
                }
                if (any)
                    g.tree().addLeaf(leaf);
                else
                    delete leaf;
            }
    g.tree().setValue(Coord(0, 0, 0), 0.5f);
    g.tree().setValue(Coord(2 * c, 2 * c, 2 * c), 0.5f);
}

/* A Mitsuba .vol's voxels and box. */
void vol(Spec &g, const std::string &path)
{
    std::ifstream in(path, std::ios::binary);
    char h[48];
    if (!in.read(h, 48) || h[0] != 'V' || h[1] != 'O' || h[2] != 'L')
        die("cannot read " + path);
    int32_t r[5];
    float box[6];
    std::memcpy(r, h + 4, 20);
    std::memcpy(box, h + 24, 24);
    if (r[0] != 1 || r[4] != 1)
        die(path + ": not a 1-channel float32 .vol");
    std::vector<float> v(static_cast<size_t>(r[1]) * r[2] * r[3]);
    if (!in.read(reinterpret_cast<char *>(v.data()), static_cast<std::streamsize>(v.size() * 4)))
        die(path + ": truncated");
    openvdb::Mat4d m = openvdb::Mat4d::identity();
    for (int a = 0; a < 3; a++) {
        double hsz = (static_cast<double>(box[3 + a]) - box[a]) / r[1 + a];
        m(a, a) = hsz;
        m(3, a) = box[a] + 0.5 * hsz; /* voxel 0's centre */
    }
    g.xf = openvdb::math::Transform::createLinearTransform(m);
    size_t i = 0;
    for (int z = 0; z < r[3]; z++)
        for (int y = 0; y < r[2]; y++)
            for (int x = 0; x < r[1]; x++, i++)
                if (v[i] != 0.0f)
                    set(g, Coord(x, y, z), v[i], true);
}

void start(Spec &g, const std::string &name, const std::string &type)
{
    g = Spec();
    g.name = name;
    g.type = type;
    if (type == "float" || type == "half" || type == "levelset")
        g.f = openvdb::FloatGrid::create(0.0f);
    else if (type == "double")
        g.d = openvdb::DoubleGrid::create(0.0);
    else if (type == "vec3s")
        g.v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    else if (type == "int32")
        g.i = openvdb::Int32Grid::create(0);
    else
        die("unknown grid type " + type);
}

openvdb::GridBase::Ptr finish(Spec &g)
{
    openvdb::GridBase::Ptr b;
    if (g.f)
        b = g.f;
    else if (g.d)
        b = g.d;
    else if (g.v)
        b = g.v;
    else
        b = g.i;
    b->setName(g.name);
    b->setTransform(g.xf);
    b->setGridClass(g.type == "levelset" ? openvdb::GRID_LEVEL_SET : openvdb::GRID_FOG_VOLUME);
    b->setSaveFloatAsHalf(g.type == "half");
    return b;
}

} // namespace

int main(int argc, char **argv)
{
    if (argc != 2)
        die("usage: vdb_write OUT.vdb < SPEC");
    openvdb::initialize();
    openvdb::GridPtrVec grids;
    Spec g;
    bool have = false;
    uint32_t compression = openvdb::io::COMPRESS_ACTIVE_MASK;
    std::string line;
    while (std::getline(std::cin, line)) {
        std::istringstream in(line.substr(0, line.find('#')));
        std::string cmd;
        if (!(in >> cmd))
            continue;
        if (cmd == "grid") {
            std::string name, type;
            in >> name >> type;
            if (have)
                grids.push_back(finish(g));
            start(g, name, type);
            have = true;
            continue;
        }
        if (cmd == "compress") {
            std::string c;
            in >> c;
            uint32_t zip = openvdb::io::COMPRESS_ZIP, blosc = openvdb::io::COMPRESS_BLOSC;
            compression = openvdb::io::COMPRESS_ACTIVE_MASK | (c == "zip" ? zip : c == "blosc" ? blosc : 0u);
            continue;
        }
        if (!have)
            die("'" + cmd + "' before any grid");
        if (cmd == "map") {
            double s[3], t[3], r[3] = {0, 0, 0};
            in >> s[0] >> s[1] >> s[2] >> t[0] >> t[1] >> t[2];
            if (!in.fail() && !in.eof() && !(in >> std::ws).eof())
                in >> r[0] >> r[1] >> r[2];
            else if (!in.fail())
                in.clear(); /* no rotation: the eof of reading past the last number is not a failure */
            g.xf = openvdb::math::Transform::createLinearTransform(1.0);
            g.xf->preScale(openvdb::Vec3d(s[0], s[1], s[2]));
            for (int a = 0; a < 3; a++)
                if (r[a] != 0.0)
                    g.xf->postRotate(r[a] * M_PI / 180.0, a == 0 ? openvdb::math::X_AXIS
                                                         : a == 1 ? openvdb::math::Y_AXIS : openvdb::math::Z_AXIS);
            g.xf->postTranslate(openvdb::Vec3d(t[0], t[1], t[2]));
        } else if (cmd == "frustum") {
            g.xf = openvdb::math::Transform::createFrustumTransform(
                openvdb::BBoxd(openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(16, 16, 16)), 0.5, 1.0, 1.0);
        } else if (cmd == "background") {
            double v;
            in >> v;
            if (g.f)
                g.f->tree().root().setBackground(static_cast<float>(v), true);
            else if (g.d)
                g.d->tree().root().setBackground(v, true);
        } else if (cmd == "voxel" || cmd == "inactive") {
            int x, y, z;
            std::string word;
            in >> x >> y >> z >> word;
            char *end = nullptr;
            double v = std::strtod(word.c_str(), &end); /* strtod: also nan and inf, which >> refuses */
            if (word.empty() || *end)
                die("not a number: " + word);
            set(g, Coord(x, y, z), v, cmd == "voxel");
        } else if (cmd == "fill") {
            int b[6];
            double v;
            in >> b[0] >> b[1] >> b[2] >> b[3] >> b[4] >> b[5] >> v;
            openvdb::CoordBBox bb(Coord(b[0], b[1], b[2]), Coord(b[3], b[4], b[5]));
            if (g.f)
                g.f->tree().fill(bb, static_cast<float>(v), true);
            else if (g.d)
                g.d->tree().fill(bb, v, true);
            else
                die("fill: float or double grids only");
        } else if (cmd == "vol") {
            std::string path;
            in >> path;
            vol(g, path);
        } else if (cmd == "checker") {
            int o[3], n;
            double a, b;
            in >> o[0] >> o[1] >> o[2] >> n >> a >> b;
            for (int z = 0; z < n; z++)
                for (int y = 0; y < n; y++)
                    for (int x = 0; x < n; x++)
                        set(g, Coord(o[0] + x, o[1] + y, o[2] + z), ((x + y + z) & 1) ? b : a, true);
        } else if (cmd == "ball") {
            int c;
            double r;
            in >> c >> r;
            if (!g.f)
                die("ball: float grids only");
            ball(*g.f, c, r);
        } else {
            die("unknown command '" + cmd + "'");
        }
        if (in.fail())
            die("bad arguments in: " + line);
    }
    if (!have)
        die("no grid");
    grids.push_back(finish(g));
    openvdb::io::File file(argv[1]);
    file.setCompression(compression);
    file.write(grids);
    file.close();
    return 0;
}
