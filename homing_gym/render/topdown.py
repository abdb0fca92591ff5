"""Pictures of an episode: the top-down map and the frame ``render("rgb_array")`` returns."""

from __future__ import annotations

import math

import cv2
import numpy as np

from homing_gym.scenes.base import Scene
from homing_gym.scenes.footprint import band_faces

BG = (245, 245, 240)
WALL = (60, 60, 60)
FENCE = (170, 170, 170)
HOME = (30, 150, 60)
ROBOT = (40, 90, 200)
PATH = (230, 120, 30)


class MapCanvas:
    """Maps floor coordinates (metres) to pixels of a square top-down picture."""

    def __init__(self, scene: Scene, size: int = 360, margin: float = 0.15):
        (xmin, ymin), (xmax, ymax) = scene.bounds
        span = max(xmax - xmin, ymax - ymin) + 2 * margin
        self.scale = size / span
        self.cx, self.cy = (xmin + xmax) / 2, (ymin + ymax) / 2
        self.size = size

    def px(self, x: float, y: float) -> tuple[int, int]:
        """Pixel of floor point (x, y); +x to the right, +y up."""
        return (int(round(self.size / 2 + (x - self.cx) * self.scale)),
                int(round(self.size / 2 - (y - self.cy) * self.scale)))

    def length(self, metres: float) -> int:
        return max(1, int(round(metres * self.scale)))


def draw_scene(scene: Scene, canvas: MapCanvas) -> np.ndarray:
    """The fence (thin grey), mesh footprints, walls and landmarks (in their own colours)
    on a light background, RGB uint8."""
    img = np.full((canvas.size, canvas.size, 3), BG, np.uint8)
    if scene.fence:                       # the invisible boundary, thin
        (xmin, ymin), (xmax, ymax) = scene.bounds
        cv2.rectangle(img, canvas.px(xmin, ymax), canvas.px(xmax, ymin), FENCE, 1, cv2.LINE_AA)
    _draw_meshes(img, scene, canvas)
    for wall in scene.walls:
        cv2.line(img, canvas.px(*wall.start), canvas.px(*wall.end), WALL,
                 canvas.length(wall.thickness), cv2.LINE_AA)
    for lm in scene.landmarks:
        color = tuple(int(255 * c) for c in lm.color[:3])
        if lm.shape == "cylinder":
            cv2.circle(img, canvas.px(*lm.position), canvas.length(lm.radius), color, -1,
                       cv2.LINE_AA)
        else:
            c, s = math.cos(lm.yaw), math.sin(lm.yaw)
            hx, hy = lm.extent[0] / 2, lm.extent[1] / 2
            corners = [(lm.position[0] + c * u - s * v, lm.position[1] + s * u + c * v)
                       for u, v in ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))]
            cv2.fillPoly(img, [np.array([canvas.px(*q) for q in corners], np.int32)], color,
                         cv2.LINE_AA)
    return img


def _draw_meshes(img: np.ndarray, scene: Scene, canvas: MapCanvas) -> None:
    """The faces of mesh parts that reach into the scene's height band, seen from above in
    their colours (lower faces first; parts the robot passes through lighter)."""
    faces, colors, tops = [], [], []
    for part in scene.meshes:
        index = band_faces(part, scene.height_band)
        tris = part.triangles[index]
        faces.append(tris[:, :, :2])
        colors.append(part.face_colors[index] if part.collision
                      else 0.5 + 0.5 * part.face_colors[index])
        tops.append(tris[:, :, 2].max(axis=1))
    if not faces:
        return
    order = np.argsort(np.concatenate(tops), kind="stable")
    faces, colors = np.concatenate(faces)[order], np.concatenate(colors)[order]
    for tri, color in zip(faces, colors):
        pts = np.array([canvas.px(*q) for q in tri], np.int32)
        bgr = tuple(int(255 * c) for c in color)
        cv2.fillPoly(img, [pts], bgr, cv2.LINE_AA)
        cv2.polylines(img, [pts], True, bgr, 1, cv2.LINE_AA)


def draw_scale_bar(img: np.ndarray, canvas: MapCanvas, metres: float = 0.5) -> None:
    """A ``metres`` scale bar in the map's lower left corner."""
    h = img.shape[0]
    x0, y = 10, h - 12
    x1 = x0 + canvas.length(metres)
    cv2.line(img, (x0, y), (x1, y), (0, 0, 0), 2)
    for x in (x0, x1):
        cv2.line(img, (x, y - 4), (x, y + 4), (0, 0, 0), 1)
    cv2.putText(img, f"{metres:g} m", (x0, y - 7), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 1,
                cv2.LINE_AA)


def draw_pose(img: np.ndarray, canvas: MapCanvas, pose, radius: float, color,
              filled: bool = True) -> None:
    """A robot-sized disc with a heading tick."""
    centre = canvas.px(pose[0], pose[1])
    cv2.circle(img, centre, canvas.length(radius), color, -1 if filled else 2, cv2.LINE_AA)
    tip = canvas.px(pose[0] + 1.6 * radius * math.cos(pose[2]),
                    pose[1] + 1.6 * radius * math.sin(pose[2]))
    cv2.line(img, centre, tip, (20, 20, 20) if filled else color, 2, cv2.LINE_AA)


def draw_topdown(scene: Scene, pose, home, trajectory, robot_radius: float = 0.16,
                 success_radius: float | None = None, size: int = 360,
                 waypoints=()) -> np.ndarray:
    """Top-down map: scene, the episode's goals (small green dots), the current goal
    ``home`` (green, with the success circle), the path so far (orange) and the robot
    (blue, heading tick). RGB uint8 ``(size, size, 3)``."""
    canvas = MapCanvas(scene, size)
    img = draw_scene(scene, canvas)
    for waypoint in waypoints:
        cv2.circle(img, canvas.px(waypoint[0], waypoint[1]), 3, HOME, -1, cv2.LINE_AA)
    if success_radius is not None:
        cv2.circle(img, canvas.px(home[0], home[1]), canvas.length(success_radius), HOME, 1,
                   cv2.LINE_AA)
    draw_pose(img, canvas, home, robot_radius, HOME, filled=False)
    if len(trajectory) > 1:
        pts = np.array([canvas.px(x, y) for x, y in trajectory], np.int32)
        cv2.polylines(img, [pts], False, PATH, 2, cv2.LINE_AA)
    draw_pose(img, canvas, pose, robot_radius, ROBOT)
    return img


def labelled(image: np.ndarray, label: str, width: int) -> np.ndarray:
    """``image`` scaled to ``width`` pixels under a bar with ``label``, RGB uint8."""
    scaled = cv2.resize(image, (width, max(1, round(image.shape[0] * width / image.shape[1]))),
                        interpolation=cv2.INTER_NEAREST)
    bar = np.full((22, width, 3), BG, np.uint8)
    cv2.putText(bar, label, (6, 16), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (20, 20, 20), 1, cv2.LINE_AA)
    return np.concatenate([bar, scaled], axis=0)


def compose_frame(topdown: np.ndarray, panorama: np.ndarray, goal: np.ndarray,
                  caption: str = "") -> np.ndarray:
    """The top-down map beside the current and goal panoramas (labelled), RGB uint8."""
    size = topdown.shape[0]
    width = 2 * size
    right = np.concatenate([labelled(panorama, "current view " + caption, width),
                            labelled(goal, "goal snapshot", width)], axis=0)
    if right.shape[0] < size:
        right = np.concatenate(
            [right, np.full((size - right.shape[0], width, 3), BG, np.uint8)], axis=0)
    left = topdown
    if left.shape[0] < right.shape[0]:
        left = np.concatenate(
            [left, np.full((right.shape[0] - size, size, 3), BG, np.uint8)], axis=0)
    return np.concatenate([left, right], axis=1)
