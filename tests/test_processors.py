"""The pipeline as esper processors: a game's own processors and systems run where they are placed."""

from __future__ import annotations

import esper
import pytest

from framework import AABB, Hitbox, Scene, Transform, Velocity
from framework.scene import STAGES
from framework.systems import BroadPhase, Movement, NarrowPhase, Response, Stage

DT = 1.0 / 64.0


class Recorder(esper.Processor):
    """Appends its name (and the dt it got) to a shared log when esper runs it."""

    def __init__(self, name: str, log: list) -> None:
        self.name, self.log = name, log

    def process(self, dt: float) -> None:
        self.log.append((self.name, dt))


def stage_log(scene: Scene, log: list) -> None:
    """Make every stage of ``scene`` log its name when it runs (wrapping its run method)."""
    for stage in scene._stages.values():
        run = stage.run

        def logged(frame, run=run, name=stage.name):
            log.append((name, None))
            return run(frame)

        stage.run = logged


def test_the_stages_are_esper_processors_of_the_scenes_world_in_pipeline_order():
    with Scene() as s:
        s.spawn(Transform(0, 0), Velocity(1, 0), Hitbox(AABB(1, 1)))
        procs = esper._processors  # the scene's world is current after spawn
        stages = [p for p in procs if isinstance(p, Stage)]
        assert tuple(p.name for p in stages) == STAGES
        assert isinstance(esper.get_processor(Movement), Movement)
        assert isinstance(esper.get_processor(NarrowPhase), NarrowPhase)


def test_game_processors_run_before_and_after_the_stages_they_name():
    log: list = []
    with Scene(effects={"movement", "detection", "events", "response"}) as s:
        s.spawn(Transform(0, 0), Velocity(1, 0), Hitbox(AABB(1, 1)))
        stage_log(s, log)
        s.add_processor(Recorder("after-response", log))  # the default place
        s.add_processor(Recorder("before-broad", log), before="broad_phase")
        s.add_processor(Recorder("after-movement", log), after="movement")
        s.add_processor(Recorder("before-movement", log), before="movement")
        s.add_system(lambda scene, dt: log.append(("system-after-narrow", dt)), after="narrow_phase")
        s.add_processor(Recorder("before-narrow", log), before="narrow_phase")
        s.step(DT)
    names = [n for n, _ in log]
    # (stages the scene's effects do not call for, ccd, sleeping and render here, do not run)
    assert names == ["before-movement", "movement", "after-movement", "before-broad", "broad_phase",
                     "before-narrow", "narrow_phase", "system-after-narrow", "response", "after-response"]
    assert all(dt == DT for n, dt in log if dt is not None)  # esper passes the step's dt


def test_processors_at_one_place_run_in_the_order_they_were_added():
    log: list = []
    with Scene() as s:
        for name in "abc":
            s.add_processor(Recorder(name, log), after="response")
        s.step(DT)
    assert [n for n, _ in log] == ["a", "b", "c"]


def test_a_processor_added_with_plain_esper_runs_after_the_whole_pipeline():
    log: list = []
    with Scene(effects={"movement"}) as s:
        stage_log(s, log)
        s.add_system(lambda scene, dt: None)  # switches esper to the scene's world
        esper.add_processor(Recorder("plain-esper", log))
        s.step(DT)
    assert [n for n, _ in log][-1] == "plain-esper"


def test_a_processor_sees_the_stages_results_through_esper_components():
    """A processor after the response reads the Transform the response left (the box pushed out of
    the floor), through esper's own queries."""
    seen: list = []

    class Heights(esper.Processor):
        def process(self, dt: float) -> None:
            for _e, (t, _v) in esper.get_components(Transform, Velocity):
                seen.append(t.y)

    with Scene(gravity=(0.0, -16.0)) as s:
        s.spawn(Transform(0.0, 0.0), Hitbox(AABB(8.0, 1.0), body="static"))
        s.spawn(Transform(0.0, 1.0), Velocity(0.0, 0.0), Hitbox(AABB(1.0, 1.0)))
        s.add_processor(Heights(), after="response")
        for _ in range(4):
            s.step(DT)
    assert seen == [1.0, 1.0, 1.0, 1.0]  # at rest on the floor: exactly its height, every step


def test_removing_processors_and_systems():
    log: list = []
    with Scene() as s:
        a, b = Recorder("a", log), Recorder("b", log)
        s.add_processor(a)
        s.add_processor(b)

        def system(scene, dt):
            log.append(("system", dt))

        s.add_system(system)
        s.remove_processor(a)
        s.remove_system(system)
        s.step(DT)
        assert [n for n, _ in log] == ["b"]
        with pytest.raises(ValueError, match="not a game processor"):
            s.remove_processor(a)
        with pytest.raises(ValueError, match="not a game processor"):
            s.remove_processor(s._stages["response"])
        with pytest.raises(ValueError, match="not in this scene"):
            s.remove_system(system)


def test_bad_placements_are_refused_and_change_nothing():
    with Scene() as s:
        before = list(esper._processors)
        with pytest.raises(ValueError, match="unknown stage 'physics'"):
            s.add_processor(Recorder("x", []), before="physics")
        with pytest.raises(ValueError, match="either before= or after="):
            s.add_processor(Recorder("x", []), before="movement", after="response")
        with pytest.raises(ValueError, match="process"):
            s.add_processor(object())
        assert esper._processors == before


def test_systems_around_render_run_only_on_the_last_substep():
    log: list = []
    with Scene(substeps=4, effects={"movement"}) as s:
        s.add_system(lambda scene, dt: log.append("render-hook"), before="render")
        s.add_system(lambda scene, dt: log.append("response-hook"), after="response")
        s.step(DT)
    assert log.count("response-hook") == 4 and log.count("render-hook") == 1


def test_each_scene_runs_only_its_own_processors():
    log: list = []
    with Scene() as one, Scene() as two:
        one.add_processor(Recorder("one", log))
        two.add_processor(Recorder("two", log))
        one.step(DT)
        two.step(DT)
        one.step(DT)
    assert [n for n, _ in log] == ["one", "two", "one"]


@pytest.mark.parametrize("stage_cls", [BroadPhase, NarrowPhase, Response])
def test_a_stage_declares_the_effects_it_needs(stage_cls):
    assert stage_cls.needs and stage_cls.needs <= {"detection", "response"}
