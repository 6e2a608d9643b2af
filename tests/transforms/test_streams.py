"""Random streams of the attacks in dataloader workers, through LeRobot's ``ImageTransforms`` (issue 13, item 2).

Contract (``SeededAttack``): every (worker, epoch) draws its own stream, whatever the attack drew before it reached
the workers (a preview in the main process); a fixed seed of the dataloader's base seed reproduces a run; persistent
workers continue their streams, so epochs still differ; a caller's generator is honoured in the main process.
"""

import os
import pickle

os.environ.setdefault("HF_HUB_OFFLINE", "1")

import pytest
import torch
from torch.utils.data import DataLoader, Dataset, get_worker_info

from lerobot_phantom.transforms import make_attack
from lerobot_phantom.transforms.lerobot_registration import register_image_transforms

transforms_module = pytest.importorskip("lerobot.datasets.transforms")

CAMERA = "observation.image"
NUM_FRAMES = 32
BATCH = 4
WORKERS = 2
EPOCHS = 2


@pytest.fixture(scope="module")
def synthetic_root(tmp_path_factory):
    from lerobot_phantom.datasets.synthetic import build_synthetic_dataset

    root = tmp_path_factory.mktemp("streams") / "tiny"
    build_synthetic_dataset(
        root, "phantom/streams", episode_lengths=(NUM_FRAMES // 2,) * 2, cameras=(CAMERA,), size=16
    )
    return root


def image_transforms(type_name, **kwargs):
    register_image_transforms()
    config = transforms_module.ImageTransformsConfig(
        enable=True,
        max_num_transforms=1,
        tfs={"phantom": transforms_module.ImageTransformConfig(type=type_name, kwargs=kwargs)},
    )
    return transforms_module.ImageTransforms(config)


def preview(transforms, image, calls=5):
    """What a user does before training: look at a few attacked frames in the main process."""
    for _ in range(calls):
        transforms(image)


def run_epochs(dataset, seed, *, epochs=EPOCHS, persistent=False):
    """Per (worker, epoch): the list of that worker's batches, in order (in-order loading deals batches round robin)."""
    loader = DataLoader(
        dataset,
        batch_size=BATCH,
        num_workers=WORKERS,
        shuffle=False,
        persistent_workers=persistent,
        generator=torch.Generator().manual_seed(seed),
    )
    streams = {}
    for epoch in range(epochs):
        for position, batch in enumerate(loader):
            streams.setdefault((position % WORKERS, epoch), []).append(batch)
    return streams


class SameFrame(Dataset):
    """Every index is the same clean frame through the transforms, so the outputs depend on the stream alone."""

    def __init__(self, frame, transforms):
        self.frame = frame
        self.transforms = transforms

    def __len__(self):
        return NUM_FRAMES

    def __getitem__(self, index):
        worker = get_worker_info()
        return {"image": self.transforms(self.frame), "worker": -1 if worker is None else worker.id}


def stream_images(streams):
    for (worker, _epoch), batches in streams.items():
        assert all(
            int(w) == worker for batch in batches for w in batch["worker"]
        )  # the round-robin assumption
    return {key: torch.cat([batch["image"] for batch in batches]) for key, batches in streams.items()}


@pytest.fixture(scope="module")
def frame(synthetic_root):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    return LeRobotDataset("phantom/streams", root=synthetic_root)[0][CAMERA]


@pytest.mark.parametrize("persistent", [False, True], ids=["fresh-workers", "persistent-workers"])
def test_every_worker_and_epoch_draws_its_own_stream_after_a_preview(frame, persistent):
    transforms = image_transforms("LaserBlinding", intensity="random", seed=0)
    preview(transforms, frame)
    images = stream_images(run_epochs(SameFrame(frame, transforms), seed=1, persistent=persistent))
    assert sorted(images) == [(w, e) for w in range(WORKERS) for e in range(EPOCHS)]
    every_output = torch.cat(list(images.values())).flatten(1)
    # 4 streams x 16 draws of a continuous alpha: no draw repeats within or across streams
    assert torch.unique(every_output, dim=0).shape[0] == every_output.shape[0] == NUM_FRAMES * EPOCHS


class PickledTransforms(Dataset):
    """``SameFrame`` whose transforms reach each worker as pickled bytes (what a "spawn" worker receives), unpickled
    on the worker's first item. (This container's shared memory is too small for a real "spawn" DataLoader.)"""

    def __init__(self, frame, transforms):
        self.frame = frame
        self.pickled = pickle.dumps(transforms)
        self.transforms = None

    def __len__(self):
        return NUM_FRAMES

    def __getitem__(self, index):
        if self.transforms is None:
            self.transforms = pickle.loads(self.pickled)
        return SameFrame(self.frame, self.transforms)[index]


def test_pickled_after_a_preview_every_worker_and_epoch_still_differs(frame):
    transforms = image_transforms("LaserBlinding", intensity="random", seed=0)
    preview(transforms, frame)
    pickled = stream_images(run_epochs(PickledTransforms(frame, transforms), seed=1))
    every_output = torch.cat(list(pickled.values())).flatten(1)
    assert torch.unique(every_output, dim=0).shape[0] == NUM_FRAMES * EPOCHS
    forked = stream_images(run_epochs(SameFrame(frame, transforms), seed=1))
    assert all(torch.equal(pickled[key], forked[key]) for key in forked)  # the same streams either way


def test_a_fixed_seed_reproduces_the_run_whatever_the_preview(frame):
    def run(preview_calls, seed):
        transforms = image_transforms("LaserBlinding", intensity="random", seed=0)
        preview(transforms, frame, preview_calls)
        return stream_images(run_epochs(SameFrame(frame, transforms), seed=seed))

    first, again, no_preview, other_seed = run(5, 1), run(5, 1), run(0, 1), run(5, 2)
    assert all(torch.equal(first[key], again[key]) for key in first)
    assert all(torch.equal(first[key], no_preview[key]) for key in first)
    assert not any(torch.equal(first[key], other_seed[key]) for key in first)


def test_the_attacks_seed_is_part_of_the_worker_stream(frame):
    def run(attack_seed):
        return stream_images(
            run_epochs(
                SameFrame(frame, image_transforms("LaserBlinding", intensity="random", seed=attack_seed)),
                seed=1,
                epochs=1,
            )
        )

    zero, seven = run(0), run(7)
    assert not any(torch.equal(zero[key], seven[key]) for key in zero)


def attacked_views(streams, clean):
    """Per (worker, epoch): which views of its batches PhantomMix attacked (a signature of the stream)."""
    signatures = {}
    for (worker, _epoch), batches in streams.items():
        flags = []
        for position, batch in enumerate(batches):
            start = (position * WORKERS + worker) * BATCH
            images = batch[CAMERA]
            assert torch.equal(batch["index"], torch.arange(start, start + images.shape[0]))
            flags += (images != clean[start : start + images.shape[0]]).flatten(1).any(1).tolist()
        signatures[(worker, _epoch)] = tuple(flags)
    return signatures


@pytest.mark.parametrize("persistent", [False, True], ids=["fresh-workers", "persistent-workers"])
def test_lerobot_dataset_with_phantom_mix_in_two_workers_over_two_epochs(synthetic_root, persistent):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    clean_dataset = LeRobotDataset("phantom/streams", root=synthetic_root)
    clean = torch.stack([clean_dataset[i][CAMERA] for i in range(NUM_FRAMES)])

    def run(seed):
        transforms = image_transforms("PhantomMix", rate=0.5)
        preview(transforms, clean[0])
        dataset = LeRobotDataset("phantom/streams", root=synthetic_root, image_transforms=transforms)
        streams = run_epochs(dataset, seed=seed, persistent=persistent)
        return streams, attacked_views(streams, clean)

    streams, signatures = run(seed=1)
    assert len(set(signatures.values())) == WORKERS * EPOCHS  # 4 distinct 16-view attack patterns
    attacked = sum(sum(flags) for flags in signatures.values())
    assert 0 < attacked < NUM_FRAMES * EPOCHS
    replay, _ = run(seed=1)
    for key, batches in streams.items():
        assert all(torch.equal(a[CAMERA], b[CAMERA]) for a, b in zip(batches, replay[key], strict=True))


def test_main_process_stream_continues_over_epochs_and_is_seeded(frame):
    def two_epochs(seed):
        attack = make_attack("laser_blinding", intensity="random", seed=seed)
        return [torch.stack([attack(frame) for _ in range(4)]) for _ in range(2)]

    first, again, other = two_epochs(3), two_epochs(3), two_epochs(4)
    assert not torch.equal(first[0], first[1])
    assert torch.equal(first[0], again[0]) and torch.equal(first[1], again[1])
    assert not torch.equal(first[0], other[0])


def test_a_callers_generator_is_honoured_in_the_main_process(frame):
    attack = make_attack("laser_blinding", intensity="random", generator=torch.Generator().manual_seed(5))
    out = attack(frame)
    params = attack.sample_params(1, *frame.shape[-2:], generator=torch.Generator().manual_seed(5))
    assert torch.equal(out, attack.apply_params(frame, params))


def test_a_callers_generator_does_not_make_workers_repeat(frame):
    attack = make_attack("laser_blinding", intensity="random", generator=torch.Generator().manual_seed(5))
    preview(attack, frame)
    images = stream_images(run_epochs(SameFrame(frame, attack), seed=1))
    every_output = torch.cat(list(images.values())).flatten(1)
    assert torch.unique(every_output, dim=0).shape[0] == NUM_FRAMES * EPOCHS
