/*
 * make_grid_vdb.cpp - writes grid.vdb, the OpenVDB file of test_grid_io
 * (tests/unit/test_grid_io.c checks what it reads against the values set
 * here). Built and run by hand where libopenvdb-dev (and libboost-dev) are
 * installed:
 *   g++ -std=c++17 make_grid_vdb.cpp -lopenvdb -lImath-3_1 -ltbb -o /tmp/make_grid_vdb
 *   /tmp/make_grid_vdb grid.vdb
 * It holds two grids: "temperature" (doubles, first, so that the first
 * float grid is not the first grid) and "density" (floats): background
 * 0.5, voxels (x, y, 7) for x in -2..2, y in 0..1 set to 100 + x + 10 y
 * except (0, 1, 7), left unset, so the dense grid reads the background
 * there; voxel size 0.25, translated by (1, 2, 3).
 */
#include <openvdb/openvdb.h>

int main(int argc, char **argv)
{
    if (argc != 2) return 2;
    openvdb::initialize();
    openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(0.25);
    xf->postTranslate(openvdb::Vec3d(1.0, 2.0, 3.0));

    openvdb::DoubleGrid::Ptr temp = openvdb::DoubleGrid::create(0.0);
    temp->setName("temperature");
    temp->setTransform(xf);
    temp->getAccessor().setValue(openvdb::Coord(0, 0, 0), 300.0);

    openvdb::FloatGrid::Ptr density = openvdb::FloatGrid::create(0.5f);
    density->setName("density");
    density->setTransform(xf);
    openvdb::FloatGrid::Accessor acc = density->getAccessor();
    for (int x = -2; x <= 2; x++)
        for (int y = 0; y <= 1; y++)
            if (x != 0 || y != 1) acc.setValue(openvdb::Coord(x, y, 7), float(100 + x + 10 * y));

    openvdb::GridPtrVec grids;
    grids.push_back(temp);
    grids.push_back(density);
    openvdb::io::File file(argv[1]);
    file.write(grids);
    file.close();
    return 0;
}
