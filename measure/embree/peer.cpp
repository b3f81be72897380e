// Embree's side of the peer benchmark (measure/embree/compare.sh): the same mesh
// and rays as Glint's `cargo bench -p glint-tests --bench peer`, read from the
// files that bench writes, traced with Embree 3's single-ray, 16-wide packet and
// stream queries, and reported in the same lines.
//
//   peer DIR TRIANGLES THREADS
//
// Build: g++ -O3 -march=native -std=c++17 peer.cpp -lembree3 -lpthread

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace {

constexpr int kRuns = 3;
constexpr size_t kBatch = 4096;

std::atomic<long long> g_bytes{0};

bool monitor(void*, ssize_t bytes, bool) {
    g_bytes += bytes;
    return true;
}

std::vector<uint32_t> read_words(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) {
        std::fprintf(stderr, "peer: cannot read %s\n", path.c_str());
        std::exit(2);
    }
    std::vector<char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    std::vector<uint32_t> words(bytes.size() / 4);
    std::copy(bytes.data(), bytes.data() + words.size() * 4, reinterpret_cast<char*>(words.data()));
    return words;
}

float as_float(uint32_t w) {
    float f;
    std::memcpy(&f, &w, 4);
    return f;
}

struct Ray {
    float o[3], d[3], t_max;
};

std::vector<Ray> read_rays(const std::string& path) {
    std::vector<uint32_t> words = read_words(path);
    std::vector<Ray> rays(words[0]);
    for (size_t i = 0; i < rays.size(); ++i) {
        const uint32_t* w = &words[1 + 7 * i];
        for (int k = 0; k < 3; ++k) {
            rays[i].o[k] = as_float(w[k]);
            rays[i].d[k] = as_float(w[3 + k]);
        }
        rays[i].t_max = as_float(w[6]);
    }
    return rays;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double median(const std::function<double()>& f) {
    std::vector<double> times;
    for (int i = 0; i < kRuns; ++i) times.push_back(f());
    std::sort(times.begin(), times.end());
    return times[kRuns / 2];
}

// Runs `work(first, count)` over batches of the rays on `threads` threads;
// returns the wall time and the sum of what the batches found.
double parallel(size_t n, int threads, const std::function<size_t(size_t, size_t)>& work, size_t& found) {
    std::atomic<size_t> next{0};
    std::atomic<size_t> total{0};
    auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) {
        pool.emplace_back([&] {
            size_t mine = 0;
            for (size_t first; (first = next.fetch_add(kBatch)) < n;) {
                mine += work(first, std::min(kBatch, n - first));
            }
            total += mine;
        });
    }
    for (auto& thread : pool) thread.join();
    found = total;
    return seconds_since(start);
}

void set_ray(RTCRay& r, const Ray& ray) {
    r.org_x = ray.o[0];
    r.org_y = ray.o[1];
    r.org_z = ray.o[2];
    r.dir_x = ray.d[0];
    r.dir_y = ray.d[1];
    r.dir_z = ray.d[2];
    r.tnear = 0.0f;
    r.tfar = ray.t_max;
    r.time = 0.0f;
    r.mask = 0xffffffff;
    r.id = 0;
    r.flags = 0;
}

template <typename Ray16>
void set_lane(Ray16& r, int k, const Ray& ray) {
    r.org_x[k] = ray.o[0];
    r.org_y[k] = ray.o[1];
    r.org_z[k] = ray.o[2];
    r.dir_x[k] = ray.d[0];
    r.dir_y[k] = ray.d[1];
    r.dir_z[k] = ray.d[2];
    r.tnear[k] = 0.0f;
    r.tfar[k] = ray.t_max;
    r.time[k] = 0.0f;
    r.mask[k] = 0xffffffff;
    r.id[k] = 0;
    r.flags[k] = 0;
}

enum class Query { ClosestOne, ClosestPacket, ClosestStream, AnyOne, AnyPacket, AnyStream };

const char* name(Query q) {
    switch (q) {
        case Query::ClosestOne: return "closest, one ray";
        case Query::ClosestPacket: return "closest, 16 in a packet";
        case Query::ClosestStream: return "closest, stream";
        case Query::AnyOne: return "any, one ray";
        case Query::AnyPacket: return "any, 16 in a packet";
        case Query::AnyStream: return "any, stream";
    }
    return "";
}

size_t trace_batch(RTCScene scene, const std::vector<Ray>& rays, size_t first, size_t count, Query q,
                   bool coherent) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    size_t found = 0;
    // Rays i..i+15 into the lanes of a packet (the last ray repeated past the
    // batch's end, where the lanes are not valid).
    auto load16 = [&](auto& packet, int* valid, size_t i) {
        for (int k = 0; k < 16; ++k) {
            valid[k] = i + k < first + count ? -1 : 0;
            set_lane(packet, k, rays[std::min(i + k, first + count - 1)]);
        }
    };
    switch (q) {
        case Query::ClosestOne:
            for (size_t i = first; i < first + count; ++i) {
                RTCRayHit rh;
                set_ray(rh.ray, rays[i]);
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(scene, &context, &rh);
                found += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
            }
            break;
        case Query::AnyOne:
            for (size_t i = first; i < first + count; ++i) {
                RTCRay r;
                set_ray(r, rays[i]);
                rtcOccluded1(scene, &context, &r);
                found += r.tfar < 0.0f;
            }
            break;
        case Query::ClosestPacket:
            for (size_t i = first; i < first + count; i += 16) {
                alignas(64) RTCRayHit16 rh;
                alignas(64) int valid[16];
                load16(rh.ray, valid, i);
                for (int k = 0; k < 16; ++k) rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect16(valid, scene, &context, &rh);
                for (int k = 0; k < 16; ++k) found += valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
            }
            break;
        case Query::AnyPacket:
            for (size_t i = first; i < first + count; i += 16) {
                alignas(64) RTCRay16 r;
                alignas(64) int valid[16];
                load16(r, valid, i);
                rtcOccluded16(valid, scene, &context, &r);
                for (int k = 0; k < 16; ++k) found += valid[k] && r.tfar[k] < 0.0f;
            }
            break;
        case Query::ClosestStream: {
            std::vector<RTCRayHit> rh(count);
            for (size_t i = 0; i < count; ++i) {
                set_ray(rh[i].ray, rays[first + i]);
                rh[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect1M(scene, &context, rh.data(), count, sizeof(RTCRayHit));
            for (auto& h : rh) found += h.hit.geomID != RTC_INVALID_GEOMETRY_ID;
            break;
        }
        case Query::AnyStream: {
            std::vector<RTCRay> r(count);
            for (size_t i = 0; i < count; ++i) set_ray(r[i], rays[first + i]);
            rtcOccluded1M(scene, &context, r.data(), count, sizeof(RTCRay));
            for (auto& ray : r) found += ray.tfar < 0.0f;
            break;
        }
    }
    return found;
}

RTCScene build(RTCDevice device, const std::vector<uint32_t>& mesh) {
    uint32_t vertices = mesh[0], triangles = mesh[1];
    RTCScene scene = rtcNewScene(device);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* positions = static_cast<float*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices));
    auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangles));
    for (size_t i = 0; i < 3ull * vertices; ++i) positions[i] = as_float(mesh[2 + i]);
    std::copy(mesh.begin() + 2 + 3ull * vertices, mesh.begin() + 2 + 3ull * vertices + 3ull * triangles, indices);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene);
    return scene;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: peer DIR TRIANGLES THREADS\n");
        return 2;
    }
    std::string dir = argv[1], size = argv[2];
    int threads = std::atoi(argv[3]);
    std::string config = "threads=" + std::to_string(threads);
    RTCDevice device = rtcNewDevice(config.c_str());
    rtcSetDeviceMemoryMonitorFunction(device, monitor, nullptr);
    std::vector<uint32_t> mesh = read_words(dir + "/grid-" + size + ".mesh");
    uint32_t triangles = mesh[1];
    double build_time = median([&] {
        auto start = std::chrono::steady_clock::now();
        RTCScene scene = build(device, mesh);
        double t = seconds_since(start);
        rtcReleaseScene(scene);
        return t;
    });
    long long before = g_bytes;
    RTCScene scene = build(device, mesh);
    long long bytes = g_bytes - before;
    std::printf("build\t%.1f ms\n", build_time * 1e3);
    std::printf("bytes per triangle\t%.0f\n", double(bytes) / triangles);
    for (std::string kind : {"coherent", "incoherent", "shadow"}) {
        std::vector<Ray> rays = read_rays(dir + "/grid-" + size + "." + kind + ".rays");
        std::vector<Query> queries;
        if (kind == "shadow") {
            queries = {Query::AnyOne, Query::AnyPacket, Query::AnyStream};
        } else {
            queries = {Query::ClosestOne, Query::ClosestPacket, Query::ClosestStream};
        }
        if (kind == "incoherent") {
            for (Query q : {Query::AnyOne, Query::AnyPacket, Query::AnyStream}) queries.push_back(q);
        }
        for (Query q : queries) {
            bool any = q == Query::AnyOne || q == Query::AnyPacket || q == Query::AnyStream;
            std::vector<Ray> traced = rays;
            // Incoherent rays' any hits: up to distance 1, as Glint's bench.
            if (kind == "incoherent" && any) {
                for (auto& r : traced) r.t_max = 1.0f;
            }
            size_t found = 0;
            double time = median([&] {
                return parallel(traced.size(), threads, [&](size_t first, size_t count) {
                    return trace_batch(scene, traced, first, count, q, kind != "incoherent");
                }, found);
            });
            if (found == 0) {
                std::fprintf(stderr, "peer: %s %s found nothing\n", kind.c_str(), name(q));
                return 1;
            }
            std::printf("%s %s\t%.2f M rays/s\n", kind.c_str(), name(q), traced.size() / time / 1e6);
        }
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return 0;
}
