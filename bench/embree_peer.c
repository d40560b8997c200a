/* Embree 3 on the workload of bench/raycast_peers.py, as crates/sensor/examples/raycast_peer
 * times ours: the mesh's BVH built (Embree's default, high-quality-off build), then every ray
 * cast REPEATS times on THREADS threads in chunks of 4096, either as packets of 16 consecutive
 * rays (rtcIntersect16: the script's 4x4 pixel blocks) or one by one (rtcIntersect1).
 *
 *     cc -O3 -march=native bench/embree_peer.c -lembree3 -lpthread -o target/embree_peer
 *     target/embree_peer V.npy T.npy RAYS.npy THREADS REPEATS OUT.npy p16|p1
 *
 * Prints {"build_s", "best_mrays", "median_mrays", "bvh_bytes_per_triangle"} (the bytes
 * Embree's memory monitor counts for the scene, less the shared vertex and index buffers,
 * which are the caller's) and writes each ray's (t, triangle, unit normal) as float32 [n, 5]
 * (t inf and triangle -1 for a miss). */
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* An .npy file's data (version 1 or 2 header), read whole; its element count in *count. */
static void *npy(const char *path, size_t elem, size_t *count) {
    FILE *f = fopen(path, "rb");
    if (!f) { perror(path); exit(2); }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    unsigned char *bytes = malloc(size + 16); /* Embree reads 16 bytes past a vertex */
    fseek(f, 0, SEEK_SET);
    if (fread(bytes, 1, size, f) != (size_t)size) { perror(path); exit(2); }
    fclose(f);
    size_t header = bytes[6] == 1 ? 10 + (bytes[8] | bytes[9] << 8)
                                  : 12 + (bytes[8] | bytes[9] << 8 | bytes[10] << 16);
    *count = (size - header) / elem;
    memmove(bytes, bytes + header, size - header);
    return bytes;
}

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

static atomic_long allocated;
static bool monitor(void *user, ssize_t bytes, bool post) {
    (void)user; (void)post;
    atomic_fetch_add(&allocated, bytes);
    return true;
}

static RTCScene scene;
static const float *rays;
static float *out;
static size_t ray_count;
static int packets;
static atomic_size_t next_chunk;
#define CHUNK 4096

static void store(size_t i, float t, unsigned prim, float nx, float ny, float nz) {
    float *o = out + 5 * i;
    if (prim == RTC_INVALID_GEOMETRY_ID) {
        o[0] = INFINITY; o[1] = -1; o[2] = o[3] = o[4] = 0;
        return;
    }
    float len = sqrtf(nx * nx + ny * ny + nz * nz);
    o[0] = t; o[1] = (float)prim; o[2] = nx / len; o[3] = ny / len; o[4] = nz / len;
}

static void *work(void *arg) {
    (void)arg;
    struct RTCIntersectContext context;
    for (;;) {
        size_t start = atomic_fetch_add(&next_chunk, CHUNK);
        if (start >= ray_count) return NULL;
        size_t end = start + CHUNK < ray_count ? start + CHUNK : ray_count;
        for (size_t i = start; i < end; i += packets ? 16 : 1) {
            rtcInitIntersectContext(&context);
            if (packets) {
                struct RTCRayHit16 rh __attribute__((aligned(64)));
                int valid[16] __attribute__((aligned(64)));
                for (int k = 0; k < 16; k++) {
                    size_t j = i + k < end ? i + k : i;
                    const float *r = rays + 6 * j;
                    valid[k] = i + k < end ? -1 : 0;
                    rh.ray.org_x[k] = r[0]; rh.ray.org_y[k] = r[1]; rh.ray.org_z[k] = r[2];
                    rh.ray.dir_x[k] = r[3]; rh.ray.dir_y[k] = r[4]; rh.ray.dir_z[k] = r[5];
                    rh.ray.tnear[k] = 0; rh.ray.tfar[k] = INFINITY; rh.ray.time[k] = 0;
                    rh.ray.mask[k] = -1; rh.ray.flags[k] = 0; rh.ray.id[k] = k;
                    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                    rh.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
                }
                rtcIntersect16(valid, scene, &context, &rh);
                for (int k = 0; k < 16 && i + k < end; k++) {
                    unsigned prim = rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID
                                        ? RTC_INVALID_GEOMETRY_ID : rh.hit.primID[k];
                    store(i + k, rh.ray.tfar[k], prim, rh.hit.Ng_x[k], rh.hit.Ng_y[k],
                          rh.hit.Ng_z[k]);
                }
            } else {
                const float *r = rays + 6 * i;
                struct RTCRayHit rh;
                rh.ray.org_x = r[0]; rh.ray.org_y = r[1]; rh.ray.org_z = r[2];
                rh.ray.dir_x = r[3]; rh.ray.dir_y = r[4]; rh.ray.dir_z = r[5];
                rh.ray.tnear = 0; rh.ray.tfar = INFINITY; rh.ray.time = 0;
                rh.ray.mask = -1; rh.ray.flags = 0; rh.ray.id = 0;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(scene, &context, &rh);
                unsigned prim = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID
                                    ? RTC_INVALID_GEOMETRY_ID : rh.hit.primID;
                store(i, rh.ray.tfar, prim, rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
            }
        }
    }
}

static int by_value(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    if (argc != 8) {
        fprintf(stderr, "usage: %s V.npy T.npy RAYS.npy THREADS REPEATS OUT.npy p16|p1\n", argv[0]);
        return 2;
    }
    size_t floats, indices, ray_floats;
    float *vertices = npy(argv[1], 4, &floats);
    unsigned *triangles = npy(argv[2], 4, &indices);
    rays = npy(argv[3], 4, &ray_floats);
    ray_count = ray_floats / 6;
    int threads = atoi(argv[4]), repeats = atoi(argv[5]);
    packets = strcmp(argv[7], "p16") == 0;

    char config[64];
    snprintf(config, sizeof config, "threads=%d", threads);
    RTCDevice device = rtcNewDevice(config);
    rtcSetDeviceMemoryMonitorFunction(device, monitor, NULL);
    double start = now();
    scene = rtcNewScene(device);
    RTCGeometry mesh = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(mesh, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertices, 0,
                               12, floats / 3);
    rtcSetSharedGeometryBuffer(mesh, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, triangles, 0,
                               12, indices / 3);
    rtcCommitGeometry(mesh);
    rtcAttachGeometry(scene, mesh);
    rtcReleaseGeometry(mesh);
    rtcCommitScene(scene);
    double build = now() - start;
    long bytes = atomic_load(&allocated);

    out = malloc(5 * sizeof(float) * ray_count);
    double *times = malloc(sizeof(double) * repeats);
    pthread_t *pool = malloc(sizeof(pthread_t) * threads);
    for (int r = 0; r < repeats; r++) {
        atomic_store(&next_chunk, 0);
        start = now();
        for (int k = 0; k < threads; k++) pthread_create(&pool[k], NULL, work, NULL);
        for (int k = 0; k < threads; k++) pthread_join(pool[k], NULL);
        times[r] = now() - start;
    }
    qsort(times, repeats, sizeof(double), by_value);
    printf("{\"build_s\": %.4f, \"best_mrays\": %.3f, \"median_mrays\": %.3f, "
           "\"bvh_bytes_per_triangle\": %.1f}\n",
           build, ray_count / times[0] / 1e6, ray_count / times[repeats / 2] / 1e6,
           (double)bytes / (indices / 3));

    FILE *f = fopen(argv[6], "wb");
    if (!f) { perror(argv[6]); return 2; }
    char header[128];
    int len = snprintf(header, sizeof header,
                       "{'descr': '<f4', 'fortran_order': False, 'shape': (%zu, 5), }", ray_count);
    int pad = 64 - (10 + len + 1) % 64;
    fwrite("\x93NUMPY\x01\x00", 1, 8, f);
    unsigned short hl = len + pad + 1;
    fwrite(&hl, 2, 1, f);
    fwrite(header, 1, len, f);
    for (int k = 0; k < pad; k++) fputc(' ', f);
    fputc('\n', f);
    fwrite(out, sizeof(float), 5 * ray_count, f);
    fclose(f);
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return 0;
}
