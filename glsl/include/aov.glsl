// Semantic classes of the ids AOV (src/view/aov.rs, README "AOVs").
#ifndef ALPENGLOW_AOV_GLSL
#define ALPENGLOW_AOV_GLSL

const uint CLASS_SKY = 0u;
const uint CLASS_TERRAIN = 1u;     // terrain, surface layer unknown
const uint CLASS_ROCK = 2u;
const uint CLASS_SCAN = 3u;
const uint CLASS_VEGETATION = 4u;
const uint CLASS_LAYER_BASE = 10u; // terrain whose dominant layer is k: 10 + k

#endif
