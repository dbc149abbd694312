/*
 * The C API end to end: a validated context, a scene from a height array,
 * a small frame rendered blocking and then pipelined, every output read
 * into buffers this program owns and checked, a PPM written (when a path
 * is given), everything destroyed, and no validation message allowed.
 *
 *   cc -std=c99 -Iinclude capi/examples/render.c -Ltarget/debug -lalpenglow_c -lm -o render
 *   ./render [out.ppm]
 *
 * Exits 0 on success; otherwise prints the failing call and ag_last_error().
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alpenglow.h"

#define CHECK(call)                                                                  \
    do {                                                                             \
        ag_status status_ = (call);                                                  \
        if (status_ != AG_OK) {                                                      \
            fprintf(stderr, "%s failed (%d): %s\n", #call, (int)status_, ag_last_error()); \
            return 1;                                                                \
        }                                                                            \
    } while (0)

#define EXPECT(condition)                                                  \
    do {                                                                   \
        if (!(condition)) {                                                \
            fprintf(stderr, "line %d: expected %s\n", __LINE__, #condition); \
            return 1;                                                      \
        }                                                                  \
    } while (0)

enum { COLUMNS = 65, ROWS = 49, WIDTH = 64, HEIGHT = 48 };

/* Rolling hills: row r at y = 40 r metres, column c at x = 40 c metres. */
static void make_heights(float *heights) {
    for (int r = 0; r < ROWS; ++r)
        for (int c = 0; c < COLUMNS; ++c)
            heights[r * COLUMNS + c] = (float)(120.0 * sin(c * 0.15) * cos(r * 0.2) + 150.0);
}

static int write_ppm(const char *path, const unsigned char *rgba) {
    FILE *file = fopen(path, "wb");
    if (!file) return 1;
    fprintf(file, "P6\n%d %d\n255\n", WIDTH, HEIGHT);
    for (int i = 0; i < WIDTH * HEIGHT; ++i) fwrite(rgba + 4 * i, 1, 3, file);
    return fclose(file) != 0;
}

/* Buffers for one view: every output of ag_frame_buffers, sized by the renderer. */
typedef struct {
    unsigned char *rgba8;
    float *hdr, *depth, *distance, *normal, *motion;
    uint32_t *class_id, *instance_id;
    ag_frame_buffers buffers;
} outputs;

static int allocate(const ag_renderer *renderer, outputs *out) {
    void **slots[8] = {(void **)&out->rgba8, (void **)&out->hdr,    (void **)&out->depth,
                       (void **)&out->distance, (void **)&out->normal, (void **)&out->class_id,
                       (void **)&out->instance_id, (void **)&out->motion};
    ag_buffer *buffers[8] = {&out->buffers.rgba8,  &out->buffers.hdr,         &out->buffers.depth,
                             &out->buffers.distance, &out->buffers.normal,    &out->buffers.class_id,
                             &out->buffers.instance_id, &out->buffers.motion};
    for (ag_output k = AG_OUTPUT_RGBA8; k <= AG_OUTPUT_MOTION; ++k) {
        size_t bytes = 0;
        CHECK(ag_renderer_output_bytes(renderer, 0, k, &bytes));
        *slots[k] = malloc(bytes);
        EXPECT(*slots[k] != NULL);
        buffers[k]->data = *slots[k];
        buffers[k]->bytes = bytes;
    }
    EXPECT(out->buffers.hdr.bytes == (size_t)WIDTH * HEIGHT * 16);
    return 0;
}

static void release(outputs *out) {
    free(out->rgba8), free(out->hdr), free(out->depth), free(out->distance);
    free(out->normal), free(out->class_id), free(out->instance_id), free(out->motion);
}

/* Checks a frame of the hills from above: terrain and sky both visible. */
static int check_frame(const outputs *out) {
    int terrain = 0, sky = 0;
    double luminance = 0.0;
    for (int i = 0; i < WIDTH * HEIGHT; ++i) {
        int is_sky = isinf(out->depth[i]);
        sky += is_sky;
        terrain += !is_sky;
        EXPECT(out->rgba8[4 * i + 3] == 255);
        EXPECT(isfinite(out->hdr[4 * i]) && out->hdr[4 * i] >= 0.0f);
        EXPECT(!is_sky || out->class_id[i] == 0);
        EXPECT(is_sky ? isinf(out->distance[i]) : out->distance[i] >= out->depth[i] * 0.999f);
        if (!is_sky) {
            const float *n = out->normal + 3 * i;
            EXPECT(fabsf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0f) < 0.01f);
            EXPECT(out->class_id[i] != 0);
        }
        luminance += out->rgba8[4 * i] + out->rgba8[4 * i + 1] + out->rgba8[4 * i + 2];
    }
    printf("terrain %d px, sky %d px, mean sRGB %.1f\n", terrain, sky, luminance / (3.0 * WIDTH * HEIGHT));
    EXPECT(terrain > 0 && sky > 0);
    return 0;
}

int main(int argc, char **argv) {
    printf("alpenglow %s (ABI %u)\n", ag_version(), ag_abi_version());
    EXPECT(ag_abi_version() == AG_ABI_VERSION);

    ag_context_options options = {.validation = true, .device = NULL};
    ag_context *ctx = NULL;
    CHECK(ag_context_create(&options, &ctx));
    char device[256];
    CHECK(ag_context_device_name(ctx, device, sizeof device, NULL));
    printf("device: %s\n", device);

    float *heights = malloc(sizeof(float) * COLUMNS * ROWS);
    EXPECT(heights != NULL);
    make_heights(heights);

    /* A bad input is an error code and a message, not a crash. */
    ag_scene *scene = NULL;
    heights[7] = NAN;
    EXPECT(ag_scene_from_heights(heights, COLUMNS, ROWS, 40.0, 40.0, &scene) == AG_ERROR_INVALID_ARGUMENT);
    EXPECT(scene == NULL && strstr(ag_last_error(), "heights") != NULL);
    printf("NaN heights refused: %s\n", ag_last_error());
    make_heights(heights);
    CHECK(ag_scene_from_heights(heights, COLUMNS, ROWS, 40.0, 40.0, &scene));
    free(heights);

    ag_settings settings = ag_settings_default();
    settings.width = WIDTH;
    settings.height = HEIGHT;
    settings.terrain_detail = false;
    ag_renderer *renderer = NULL;
    CHECK(ag_renderer_create(ctx, scene, &settings, &renderer));
    ag_camera camera;
    CHECK(ag_scene_default_camera(scene, &camera));

    outputs out;
    memset(&out, 0, sizeof out);
    if (allocate(renderer, &out)) return 1;
    CHECK(ag_renderer_render(renderer, &camera, 1, &out.buffers, 1));
    if (check_frame(&out)) return 1;
    if (argc > 1 && write_ppm(argv[1], out.rgba8)) {
        fprintf(stderr, "cannot write %s\n", argv[1]);
        return 1;
    }

    /* Pipelined: submit two frames, then read both. */
    ag_ticket first = 0, second = 0;
    CHECK(ag_renderer_submit(renderer, &camera, 1, &first));
    CHECK(ag_renderer_submit(renderer, &camera, 1, &second));
    EXPECT(first != 0 && second == first + 1);
    ag_status polled = ag_renderer_poll(renderer, first, &out.buffers, 1);
    EXPECT(polled == AG_OK || polled == AG_NOT_READY);
    CHECK(ag_renderer_wait(renderer, first, &out.buffers, 1));
    CHECK(ag_renderer_wait(renderer, second, &out.buffers, 1));
    if (check_frame(&out)) return 1;

    /* A buffer that is too small is refused before anything is written. */
    ag_frame_buffers small = out.buffers;
    small.depth.bytes -= 1;
    EXPECT(ag_renderer_render(renderer, &camera, 1, &small, 1) == AG_ERROR_BUFFER_TOO_SMALL);
    printf("small buffer refused: %s\n", ag_last_error());

    ag_renderer_destroy(renderer);
    ag_scene_destroy(scene);
    release(&out);
    uint64_t messages = 0;
    CHECK(ag_context_destroy(ctx, &messages));
    printf("validation messages: %llu\n", (unsigned long long)messages);
    return messages != 0;
}
