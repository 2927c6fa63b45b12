// A small COLLADA mesh for tests of mesh reading, sound or damaged the way that crashes assimp.
#pragma once

#include <string>

namespace hpose::testing {

// A 0.1 x 0.1 x 0.3 m box as COLLADA, with its node moved 0.5 m along x; `count_attribute` false
// leaves the count out of the float_array, which makes Debian's assimp 5.2 crash (a damaged
// file as a mutation test found it).
inline std::string BoxCollada(bool count_attribute) {
  const std::string count = count_attribute ? " count=\"24\"" : "";
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="box" name="box">
      <mesh>
        <source id="box-pos">
          <float_array id="box-pos-array")" +
         count +
         R"(>-0.05 -0.05 0 -0.05 -0.05 0.3 -0.05 0.05 0 -0.05 0.05 0.3 0.05 -0.05 0 0.05 -0.05 0.3 0.05 0.05 0 0.05 0.05 0.3</float_array>
          <technique_common><accessor source="#box-pos-array" count="8" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
          </accessor></technique_common>
        </source>
        <vertices id="box-vtx"><input semantic="POSITION" source="#box-pos"/></vertices>
        <triangles count="12"><input semantic="VERTEX" source="#box-vtx" offset="0"/>
          <p>0 1 3 0 3 2 4 6 7 4 7 5 0 4 5 0 5 1 2 3 7 2 7 6 0 2 6 0 6 4 1 5 7 1 7 3</p></triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene">
      <node id="n" name="n"><matrix>1 0 0 0.5 0 1 0 0 0 0 1 0 0 0 0 1</matrix><instance_geometry url="#box"/></node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
}

}  // namespace hpose::testing
