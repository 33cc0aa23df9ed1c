from setuptools import find_packages, setup

package_name = 'dukw_estimation'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='DUKW-Ling team',
    maintainer_email='dev@dukw-ling.invalid',
    description='EKF node: motion, track slip, hull submersion, traction model.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'ekf_node = dukw_estimation.ekf_node:main',
            'fit_terrain = dukw_estimation.fit_terrain:main',
            'sysid = dukw_estimation.sysid_cli:main',
        ],
    },
)
