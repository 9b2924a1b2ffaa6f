/* SPDX-License-Identifier: MIT */
#include <string.h>
#include "fbx_fixtures.h"

/* Unit cube: control points 0-3 bottom (y=0), 4-7 top (y=1). */
static const double cube_points[24] = {
    0, 0, 0,  1, 0, 0,  1, 0, 1,  0, 0, 1,
    0, 1, 0,  1, 1, 0,  1, 1, 1,  0, 1, 1,
};
/* Six quads, last index of each as ~i. */
static const int32_t cube_polygons[24] = {
    0, 1, 2, ~3,   /* bottom -y */
    4, 7, 6, ~5,   /* top +y */
    0, 4, 5, ~1,   /* back -z */
    3, 2, 6, ~7,   /* front +z */
    0, 3, 7, ~4,   /* left -x */
    1, 5, 6, ~2,   /* right +x */
};
static const double face_normals[6][3] = { { 0, -1, 0 }, { 0, 1, 0 }, { 0, 0, -1 }, { 0, 0, 1 }, { -1, 0, 0 }, { 1, 0, 0 } };
static double cube_normals[72];
static double cube_uvs[48];

static const int32_t squash_indexes[4] = { 4, 5, 6, 7 };
static const double squash_deltas[12] = { 0, -0.5, 0, 0, -0.5, 0, 0, -0.5, 0, 0, -0.5, 0 };
static const int32_t grow50_indexes[3] = { 99, 1, 0 };       /* unsorted, one out of range */
static const double grow50_deltas[9] = { 5, 5, 5, 0, 0, 0, -0.25, 0, 0 };
static const int32_t grow100_indexes[1] = { 0 };
static const double grow100_deltas[3] = { -1, 0, 0 };
static const double grow_full_weights[2] = { 100, 50 };
static const double squash_full_weights[1] = { 100 };

static fbxw_shape squash_shape, grow_shapes[2];
static fbxw_channel cube_channels[2];
static fbxw_mesh meshes[2];

/* Curves: times in KTime, values in percent; flags as Maya writes them. */
static int64_t squash_times[3], grow_times[2];
static const float squash_values[3] = { 0, 100, 0 };
static const float grow_values[2] = { 0, 100 };
static const int32_t squash_flags[3] = { 0x6108, 0x6108, 0x6108 };  /* cubic | auto | time-independent | clamp-progressive */
static const int32_t grow_flags[2] = { 0x4, 0x4 };                   /* linear */
static float squash_data[12], grow_data[8];
static fbxw_curve squash_curve, grow_curve;

static const double root_points[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
static const int32_t root_polygons[3] = { 0, 1, ~2 };

void fixture_cube(fbxw_scene *scene, uint32_t version, int binary, int compress)
{
    for (int f = 0; f < 6; f++)
        for (int k = 0; k < 4; k++) {
            memcpy(cube_normals + 3 * (4 * f + k), face_normals[f], 3 * sizeof(double));
            cube_uvs[2 * (4 * f + k)] = (k == 1 || k == 2) ? 1.0 : 0.0;
            cube_uvs[2 * (4 * f + k) + 1] = k >= 2 ? 1.0 : 0.0;
        }
    uint32_t packed = 0x0D050D05u;  /* default weights 1/3, as Maya writes */
    float packed_float;
    memcpy(&packed_float, &packed, 4);
    memset(squash_data, 0, sizeof squash_data);
    memset(grow_data, 0, sizeof grow_data);
    for (int k = 0; k < 3; k++) squash_data[4 * k + 2] = packed_float;
    for (int k = 0; k < 2; k++) grow_data[4 * k + 2] = packed_float;
    for (int k = 0; k < 3; k++) squash_times[k] = FIXTURE_KTIME(k);
    grow_times[0] = FIXTURE_KTIME(0);
    grow_times[1] = FIXTURE_KTIME(2);
    squash_curve = (fbxw_curve){ 3, squash_times, squash_values, squash_flags, squash_data };
    grow_curve = (fbxw_curve){ 2, grow_times, grow_values, grow_flags, grow_data };

    squash_shape = (fbxw_shape){ "Squash", 4, squash_indexes, squash_deltas, NULL, 0 };
    grow_shapes[0] = (fbxw_shape){ "Grow100", 1, grow100_indexes, grow100_deltas, NULL, 0 };
    grow_shapes[1] = (fbxw_shape){ "Grow50", 3, grow50_indexes, grow50_deltas, NULL, 0 };
    memset(cube_channels, 0, sizeof cube_channels);
    cube_channels[0].name = "Squash";
    cube_channels[0].deform_percent = 25;
    cube_channels[0].shape_count = 1;
    cube_channels[0].shapes = &squash_shape;
    cube_channels[0].full_weight_count = 1;
    cube_channels[0].full_weights = squash_full_weights;
    cube_channels[0].curve = &squash_curve;
    cube_channels[1].name = "Grow";
    cube_channels[1].deform_percent = 0;
    cube_channels[1].deform_as_field_only = 1;
    cube_channels[1].shape_count = 2;
    cube_channels[1].shapes = grow_shapes;
    cube_channels[1].full_weight_count = 2;
    cube_channels[1].full_weights = grow_full_weights;
    cube_channels[1].curve = &grow_curve;

    memset(meshes, 0, sizeof meshes);
    meshes[0].name = "Root";
    meshes[0].control_point_count = 3;
    meshes[0].control_points = root_points;
    meshes[0].polygon_vertex_count = 3;
    meshes[0].polygon_vertex_index = root_polygons;
    meshes[0].scaling[0] = meshes[0].scaling[1] = meshes[0].scaling[2] = 2;
    meshes[0].parent = -1;
    meshes[1].name = "Box";
    meshes[1].control_point_count = 8;
    meshes[1].control_points = cube_points;
    meshes[1].polygon_vertex_count = 24;
    meshes[1].polygon_vertex_index = cube_polygons;
    meshes[1].normals = cube_normals;
    meshes[1].uvs = cube_uvs;
    meshes[1].translation[0] = 1;
    meshes[1].translation[1] = 2;
    meshes[1].translation[2] = 3;
    meshes[1].rotation[2] = 90;
    meshes[1].rotation_pivot[0] = 0.5;
    meshes[1].geometric_translation[2] = 0.25;
    meshes[1].channel_count = 2;
    meshes[1].channels = cube_channels;
    meshes[1].parent = 0;

    memset(scene, 0, sizeof *scene);
    scene->version = version;
    scene->binary = binary;
    scene->compress = compress;
    scene->stack_start = 0;
    scene->stack_stop = FIXTURE_KTIME(2);
    scene->mesh_count = 2;
    scene->meshes = meshes;
}

/* FBX 6.1 ASCII by hand (see fbx_fixtures.h). */
const char fixture_legacy61[] =
    "; FBX 6.1.0 project file\n"
    "FBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 6100\n\tCreator: \"hand\"\n}\n"
    "Objects:  {\n"
    "\tModel: \"Model::Tri\", \"Mesh\" {\n"
    "\t\tVersion: 232\n"
    "\t\tProperties60:  {\n"
    "\t\t\tProperty: \"Lcl Translation\", \"Lcl Translation\", \"A\",10,0,0\n"
    "\t\t\tProperty: \"Lcl Scaling\", \"Lcl Scaling\", \"A\",2,2,2\n"
    "\t\t\tProperty: \"Up\", \"Number\", \"A+N\",40\n"
    "\t\t}\n"
    "\t\tShading: T\n"
    "\t\tVertices: 0,0,0,1,0,0\n"
    "\t\t,0,1,0\n"
    "\t\tPolygonVertexIndex: 0,1,-3\n"
    "\t\tShape: \"Up\" {\n\t\t\tIndexes: 2\n\t\t\tVertices: 0,0,1\n\t\t\tNormals: 0,0,0\n\t\t}\n"
    "\t}\n"
    "}\n"
    "Connections:  {\n\tConnect: \"OO\", \"Model::Tri\", \"Model::Scene\"\n}\n"
    "Takes:  {\n\tCurrent: \"Take 001\"\n\tTake: \"Take 001\" {\n"
    "\t\tLocalTime: 0,92372316000\n"
    "\t\tModel: \"Model::Tri\" {\n\t\t\tChannel: \"Up\" {\n\t\t\t\tDefault: 40\n\t\t\t\tKeyVer: 4005\n"
    "\t\t\t\tKeyCount: 3\n\t\t\t\tKey: \n"
    "\t\t\t\t\t0,0,L,46186158000,100,C,n,69279237000,50,U,s,0,0,n\n"
    "\t\t\t}\n\t\t}\n\t}\n}\n";
